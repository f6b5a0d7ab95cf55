!> One writer per results folder: a lock file `<folder>/.multicor.lock`, independent of HDF5
!> file locking (which is often off on NFS and Lustre).
!>
!> The lock holds one line `host pid start-time` naming its owner, and never exists without
!> it: the line is written (and synced) to a file of this process's own,
!> `.multicor.lock.<host>.<pid>`, which is then given the lock's name by link(2), which fails
!> when the name exists (atomic, on NFS too), and its own name removed. Before, the lock was
!> created empty and its line written after: a run killed in between (`ulimit -f 0` killed it
!> there by SIGXFSZ) left an empty lock, which no later run could judge, and which refused
!> them all. Where the file system has no hard links (link fails with EPERM, ENOTSUP or
!> ENOSYS: FAT, some network shares) the lock is created exclusively and written (the
!> earlier way). An empty lock (left by an earlier version, or by a kill in that fallback) is
!> refused with a message saying how to remove it. A second run on the folder is refused
!> with the owner's line. A lock left
!> by a run that died without removing it (its pid no longer runs on this host) is stale: it is
!> taken over, and the caller gets a warning to print. The takeover renames the stale lock
!> to a name of its own before removing it, so that of two runs taking it over at once one
!> only succeeds (before, both removed it by name, the later one the earlier one's new lock,
!> and both ran in the folder). A lock from another host cannot be
!> checked and is always respected; its refusal says how to remove it once that run is gone.
!> `lock_release` removes the file; the driver calls it on every way out of a run, errors
!> included.
!>
!> A run killed between the creation of its file `.multicor.lock.<host>.<pid>` and that
!> file's removal (or between the rename of a stale lock to `.multicor.lock.stale.<host>.<pid>`
!> and its removal) leaves it: the run that takes the lock next removes those of its own host
!> whose process no longer runs (never another host's, which it cannot judge, nor a live
!> process's).
module io_lock
    use, intrinsic :: iso_c_binding, only: c_char, c_int, c_size_t, c_null_char
    use, intrinsic :: iso_fortran_env, only: int64
    use core_error, only: error_t, make_error
    use core_strings, only: to_str, split_words, string_t, parse_int, shell_word
    use io_paths, only: file_exists, remove_file, rename_file, folder_names, basename, dirname
    use io_file_writer, only: file_writer_t, system_error_text, errno_exists
    implicit none
    private
    public :: lock_t, lock_acquire, lock_release, lock_name, lock_owner_alive

    !> Name of the lock file inside the results folder.
    character(len=*), parameter :: lock_name = '.multicor.lock'

    !> A lock held (or not) on a results folder.
    type :: lock_t
        !> Path of the lock file.
        character(len=:), allocatable :: path
        !> True while this process holds the lock.
        logical :: held = .false.
    end type lock_t

    interface
        function c_getpid() bind(C, name='getpid') result(pid)
            import :: c_int
            integer(c_int) :: pid
        end function c_getpid
        function c_link_new(old, new) bind(C, name='multicor_link_new') result(err)
            import :: c_char, c_int
            character(kind=c_char), intent(in) :: old(*), new(*)
            integer(c_int) :: err
        end function c_link_new
        function c_no_hard_links(err) bind(C, name='multicor_no_hard_links') result(yes)
            import :: c_int
            integer(c_int), value :: err
            integer(c_int) :: yes
        end function c_no_hard_links
        function c_process_alive(pid) bind(C, name='multicor_process_alive') result(alive)
            import :: c_int
            integer(c_int), value :: pid
            integer(c_int) :: alive
        end function c_process_alive
        function c_gethostname(name, length) bind(C, name='gethostname') result(rc)
            import :: c_char, c_int, c_size_t
            character(kind=c_char), intent(out) :: name(*)
            integer(c_size_t), value :: length
            integer(c_int) :: rc
        end function c_gethostname
    end interface

contains

    !> Take the lock of results folder `dir` (which exists).
    subroutine lock_acquire(lock, dir, warning, error)
        !> The lock (held on success).
        type(lock_t), intent(out) :: lock
        !> The results folder.
        character(len=*), intent(in) :: dir
        !> '' or a warning to print (a stale lock was taken over).
        character(len=:), allocatable, intent(out) :: warning
        !> Set when another run holds the folder, or the lock cannot be written.
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: owner
        integer :: attempt
        logical :: created, taken
        warning = ''
        lock%path = dir//'/'//lock_name
        do attempt = 1, 3
            call try_create(lock%path, created, error)
            if (allocated(error)) return
            if (created) then
                lock%held = .true.
                call remove_dead_files(lock%path)
                return
            end if
            owner = read_owner(lock%path)
            if (len(owner) == 0 .and. .not. file_exists(lock%path)) cycle
            if (attempt == 3) exit
            if (lock_owner_alive(owner, host_name())) exit
            call set_aside_stale(lock%path, owner, taken)
            if (taken) warning = "warning: taking over the stale lock '"//lock%path//"' of a run that no longer "// &
                                 'runs (host pid start: '//owner//')'
        end do
        if (len(owner) == 0 .and. is_empty(lock%path)) then
            call make_error(error, "results folder '"//dir//"' is locked by an empty lock file '"//lock%path// &
                            "', which does not name its run: one killed as it created it (by an earlier "// &
                            'multicor version, or on a file system without hard links). If no other run writes '// &
                            'this folder, remove it (rm '//shell_word(lock%path)//') and start again')
            return
        end if
        if (len(owner) == 0) owner = 'unknown'
        call make_error(error, "results folder '"//dir//"' is in use by another run (host pid start: "//owner// &
                        "; lock file '"//lock%path//"'): wait for it to end; if that run is gone ("// &
                        owner_check(owner)//'), remove the lock (rm '//shell_word(lock%path)//') and start again')
    end subroutine lock_acquire

    !> How to check that the run of the owner line `owner` is gone: a job killed with its
    !> node (Slurm requeues it on another) leaves its lock, which no later run can judge.
    function owner_check(owner) result(text)
        character(len=*), intent(in) :: owner
        character(len=:), allocatable :: text
        type(string_t), allocatable :: words(:)
        text = 'its job ended or was killed, or its node failed'
        call split_words(owner, words)
        if (size(words) < 2) return
        text = text//'; on host '//words(1)%s//', ps -p '//words(2)%s//' -o args shows no multicor'
    end function owner_check

    !> Remove the files that runs of this host killed while taking a lock of this folder left
    !> (`<lock>.<host>.<pid>`, `<lock>.stale.<host>.<pid>`), whose process no longer runs.
    !> Files of another host, or of a process that runs (perhaps another run taking the lock
    !> now), are left.
    subroutine remove_dead_files(path)
        !> Path of the lock (held).
        character(len=*), intent(in) :: path
        type(string_t), allocatable :: names(:)
        character(len=:), allocatable :: prefix, rest, host, own
        integer :: k
        host = host_name()
        own = to_str(int(c_getpid()))
        prefix = basename(path)//'.'
        call folder_names(dirname(path), prefix, names)
        do k = 1, size(names)
            rest = names(k)%s(len(prefix) + 1:)
            if (len(rest) > 6) then
                if (rest(1:6) == 'stale.' .and. .not. dead_process(rest)) rest = rest(7:)
            end if
            if (dead_process(rest)) call remove_file(dirname(path)//'/'//names(k)%s)
        end do
    contains
        !> Whether `name` is '<host>.<pid>' of this host and a process that no longer runs.
        logical function dead_process(name)
            character(len=*), intent(in) :: name
            character(len=:), allocatable :: digits
            integer :: pid
            logical :: ok
            dead_process = .false.
            if (len(name) <= len(host) + 1) return
            if (name(:len(host) + 1) /= host//'.') return
            digits = name(len(host) + 2:)
            if (verify(digits, '0123456789') /= 0 .or. digits == own) return
            call parse_int(digits, pid, ok)
            if (.not. ok .or. pid <= 0) return
            dead_process = c_process_alive(int(pid, c_int)) == 0
        end function dead_process
    end subroutine remove_dead_files

    !> Remove the lock file if this process holds it.
    subroutine lock_release(lock)
        !> The lock.
        type(lock_t), intent(inout) :: lock
        if (.not. lock%held) return
        call remove_file(lock%path)
        lock%held = .false.
    end subroutine lock_release

    !> Whether the owner line `host pid ...` names a process that may still run: always true
    !> for another host (it cannot be checked) or an unreadable line; on this host, false only
    !> when kill(pid, 0) says there is no such process.
    logical function lock_owner_alive(owner, this_host) result(alive)
        !> The lock file's line.
        character(len=*), intent(in) :: owner
        !> Name of this host.
        character(len=*), intent(in) :: this_host
        type(string_t), allocatable :: words(:)
        integer :: pid
        logical :: ok
        alive = .true.
        call split_words(owner, words)
        if (size(words) < 2) return
        if (words(1)%s /= this_host) return
        call parse_int(words(2)%s, pid, ok)
        if (.not. ok .or. pid <= 0) return
        alive = c_process_alive(int(pid, c_int)) /= 0
    end function lock_owner_alive

    !> Create the lock file with its owner line; `created` is false when it exists already.
    !> The line goes to a file of this process's own, linked to the lock's name (link(2)
    !> fails when the name exists), so that the lock never exists without its line.
    subroutine try_create(path, created, error)
        character(len=*), intent(in) :: path
        logical, intent(out) :: created
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: own, line
        integer :: code
        character(len=8) :: date
        character(len=10) :: time
        created = .false.
        call date_and_time(date, time)
        line = host_name()//' '//to_str(int(c_getpid()))//' '// &
               date(1:4)//'-'//date(5:6)//'-'//date(7:8)//'T'//time(1:2)//':'//time(3:4)//':'//time(5:6)
        own = path//'.'//host_name()//'.'//to_str(int(c_getpid()))
        call write_line_to(own, line, .false., code, error)
        if (allocated(error)) then
            error%message = "cannot create the lock file '"//path//"': "//error%message
            return
        end if
        code = int(c_link_new(own//c_null_char, path//c_null_char))
        call remove_file(own)
        if (code == 0) then
            created = .true.
        else if (errno_exists(code)) then
            return
        else if (c_no_hard_links(int(code, c_int)) /= 0) then
            ! no hard links here: an exclusive create, then the line
            call write_line_to(path, line, .true., code, error)
            if (errno_exists(code)) return
            if (allocated(error)) then
                error%message = "cannot create the lock file '"//path//"': "//error%message
                return
            end if
            created = .true.
        else
            call make_error(error, "cannot create the lock file '"//path//"': "//system_error_text(code))
        end if
    end subroutine try_create

    !> Create `path` (when `exclusive`, only if it does not exist: `code` is then EEXIST) and
    !> write `line` into it; on a failure the file is removed and `error` gives the reason.
    subroutine write_line_to(path, line, exclusive, code, error)
        character(len=*), intent(in) :: path, line
        logical, intent(in) :: exclusive
        integer, intent(out) :: code
        type(error_t), allocatable, intent(out) :: error
        type(file_writer_t) :: w
        call w%create(path, '', error, exclusive=exclusive, code=code)
        if (errno_exists(code) .and. exclusive) then
            deallocate (error)
            return
        end if
        if (allocated(error)) then
            error%message = system_error_text(code)
            return
        end if
        call w%write_line(line)
        call w%close(error, code)
        if (allocated(error)) then
            call remove_file(path)
            error%message = system_error_text(code)
        end if
    end subroutine write_line_to

    !> Remove the stale lock at `path` whose owner line is `owner`, in a way that two runs
    !> taking it over at once cannot both do: rename(2) moves it to a name of this process's
    !> own (of two renames of one file, one fails), and only a file that still names `owner`
    !> there is removed. A lock that another run made after `owner`'s was read (that run took
    !> the stale one over first) is linked back to its name. `taken`: the stale lock is gone.
    subroutine set_aside_stale(path, owner, taken)
        character(len=*), intent(in) :: path, owner
        logical, intent(out) :: taken
        character(len=:), allocatable :: aside
        type(error_t), allocatable :: error
        integer :: code
        taken = .false.
        aside = path//'.stale.'//host_name()//'.'//to_str(int(c_getpid()))
        call rename_file(path, aside, error)
        ! gone already: another run took it over (its own lock, if any, is judged next)
        if (allocated(error)) return
        if (read_owner(aside) == owner) then
            taken = .true.
        else
            code = int(c_link_new(aside//c_null_char, path//c_null_char))
        end if
        call remove_file(aside)
    end subroutine set_aside_stale

    !> Whether the file `path` exists and holds no byte.
    logical function is_empty(path)
        character(len=*), intent(in) :: path
        integer(int64) :: size_bytes
        inquire (file=path, size=size_bytes)
        is_empty = size_bytes == 0
    end function is_empty

    !> The owner line of a lock file ('' when it cannot be read).
    function read_owner(path) result(owner)
        character(len=*), intent(in) :: path
        character(len=:), allocatable :: owner
        character(len=512) :: line
        integer :: unit, ios
        owner = ''
        open (newunit=unit, file=path, status='old', action='read', iostat=ios)
        if (ios /= 0) return
        read (unit, '(a)', iostat=ios) line
        close (unit)
        if (ios == 0) owner = trim(line)
    end function read_owner

    !> Name of this host ('localhost' when unknown).
    function host_name() result(name)
        character(len=:), allocatable :: name
        character(kind=c_char, len=256) :: buf
        integer :: n
        buf = ''
        if (c_gethostname(buf, int(len(buf) - 1, c_size_t)) /= 0) then
            name = 'localhost'
            return
        end if
        n = index(buf, c_null_char) - 1
        if (n < 0) n = len_trim(buf)
        name = buf(:n)
        if (len(name) == 0) name = 'localhost'
    end function host_name
end module io_lock
