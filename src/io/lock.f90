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
!> with the owner's line. A lock from another host cannot be checked and is always
!> respected; its refusal says how to remove it once that run is gone. `lock_release`
!> removes the file if it still holds the run's line (a run never removes another's lock);
!> the driver calls it on every way out of a run, errors included.
!>
!> A lock left by a run that died without removing it (its pid no longer runs on this host)
!> is stale: it is taken over, and the caller gets a warning to print. Only a run holding a
!> second lock, `<lock>.break` (taken the same way: its line's file linked to that name),
!> removes a stale lock, and only when the lock, read again while it holds `.break`, still
!> holds the dead owner's line; a run that fails to create a lock never removes one. So a
!> stale lock is removed once, and a new lock never: of runs taking one stale lock over at
!> once, one holds `.break` and the others are refused (`.break` is held), or find the new
!> lock of the one that took it over (its owner runs). Mercurial's lock breaks stale locks
!> so. Before, the stale lock was renamed to a name of the run's own, read there, and linked
!> back when it was not the one read before: a run B that had read the stale line renamed
!> the new lock of a run A that had taken it over meanwhile, a run C created its lock at the
!> free name before B linked A's back, and B removed A's lock: A and C both ran in the folder
!> (tests/regression/test_lock_takeover.py holds B there with strace delays). A `.break`
!> left by a run killed while it held it (its owner no longer runs) is stale in its turn, and
!> broken the same way under `<lock>.break.break` (and so on): no step of a takeover relies
!> on more than link(2)'s atomicity (or O_EXCL's, without hard links) and the owner's line
!> (a dead run's pid taken by a new process reads as alive: the safe side), so neither a kill
!> at any moment nor any number of simultaneous starts lets two runs hold the folder. A
!> `.break` held by a run that runs (or another host's, or an empty one) refuses the
!> takeover, with its line and how to remove it.
!>
!> A run killed between the creation of its file `.multicor.lock.<host>.<pid>` (or
!> `.multicor.lock.break.<host>.<pid>`, ...) and that file's removal leaves it: the run that
!> takes the lock next removes those of its own host whose process no longer runs (never
!> another host's, which it cannot judge, nor a live process's), with the
!> `.multicor.lock.stale.<host>.<pid>` files of earlier versions, and breaks a `.break` of a
!> dead run of its host.
module io_lock
    use, intrinsic :: iso_c_binding, only: c_char, c_int, c_size_t, c_null_char
    use, intrinsic :: iso_fortran_env, only: int64
    use core_error, only: error_t, make_error
    use core_strings, only: to_str, split_words, string_t, parse_int, shell_word
    use io_paths, only: file_exists, remove_file, folder_names, basename, dirname
    use io_file_writer, only: file_writer_t, system_error_text, errno_exists
    implicit none
    private
    public :: lock_t, lock_acquire, lock_release, lock_name, lock_owner_alive

    !> Name of the lock file inside the results folder.
    character(len=*), parameter :: lock_name = '.multicor.lock'

    !> Suffix of the lock held while a stale lock is removed (`<lock>.break`).
    character(len=*), parameter :: break_suffix = '.break'

    !> A lock held (or not) on a results folder.
    type :: lock_t
        !> Path of the lock file.
        character(len=:), allocatable :: path
        !> The owner line this process wrote into it ('' when not held).
        character(len=:), allocatable :: line
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
        character(len=:), allocatable :: owner, blocker
        integer :: attempt
        logical :: created, taken
        warning = ''
        blocker = ''
        lock%path = dir//'/'//lock_name
        lock%line = ''
        do attempt = 1, 3
            call try_create(lock%path, lock%line, created, error)
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
            call break_stale(lock%path, owner, taken, blocker, error)
            if (allocated(error)) return
            if (taken) warning = "warning: taking over the stale lock '"//lock%path//"' of a run that no longer "// &
                                 'runs (host pid start: '//owner//')'
        end do
        lock%line = ''
        if (len(owner) == 0 .and. is_empty(lock%path)) then
            call make_error(error, "results folder '"//dir//"' is locked by an empty lock file '"//lock%path// &
                            "', which does not name its run: one killed as it created it (by an earlier "// &
                            'multicor version, or on a file system without hard links). If no other run writes '// &
                            'this folder, remove it (rm '//shell_word(lock%path)//') and start again')
            return
        end if
        if (len(owner) == 0) owner = 'unknown'
        if (len(blocker) > 0 .and. .not. lock_owner_alive(owner, host_name())) then
            call make_error(error, blocked_message(dir, lock%path, owner, blocker))
            return
        end if
        call make_error(error, "results folder '"//dir//"' is in use by another run (host pid start: "//owner// &
                        "; lock file '"//lock%path//"'): wait for it to end; if that run is gone ("// &
                        owner_check(owner)//'), remove the lock (rm '//shell_word(lock%path)//') and start again')
    end subroutine lock_acquire

    !> The refusal of a run that found the lock `path` of folder `dir` stale (its owner line
    !> `owner` names a run of this host that no longer runs) but could not take `blocker` (a
    !> `.break` lock), which another run holds while it takes the stale lock over.
    function blocked_message(dir, path, owner, blocker) result(text)
        character(len=*), intent(in) :: dir, path, owner, blocker
        character(len=:), allocatable :: text, holder
        holder = read_owner(blocker)
        if (len(holder) == 0 .and. is_empty(blocker)) then
            text = "results folder '"//dir//"': its lock '"//path//"' is stale (host pid start: "//owner// &
                   ", a run that no longer runs), but the lock file '"//blocker//"' that guards its takeover is "// &
                   'empty, which does not name its run: one killed as it created it (on a file system without hard '// &
                   'links). If no other run writes this folder, remove it (rm '//shell_word(blocker)//') and start again'
            return
        end if
        if (len(holder) == 0) holder = 'unknown'
        text = "results folder '"//dir//"' is in use by another run (host pid start: "//holder//"; lock file '"// &
               blocker//"'), which takes over its stale lock '"//path//"' (host pid start: "//owner// &
               ', a run that no longer runs): start again once it has (this run is then refused while that one '// &
               'runs); if that run is gone ('//owner_check(holder)//'), remove its lock (rm '//shell_word(blocker)// &
               ') and start again'
    end function blocked_message

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

    !> Remove the stale lock at `path`, whose owner line `owner` names a run of this host that
    !> no longer runs, holding `<path>.break` meanwhile: the lock is read again there and
    !> removed only if it still holds `owner` (a run that took it over first has made a new
    !> one). A stale `<path>.break` (its holder killed in here) is broken the same way, under
    !> `<path>.break.break`. `taken`: this run removed the stale lock. `blocker`: '' or the
    !> `.break` lock that another run holds (or that cannot be judged: another host's, empty),
    !> when this run could not take it.
    recursive subroutine break_stale(path, owner, taken, blocker, error)
        !> Path of the stale lock.
        character(len=*), intent(in) :: path
        !> Its owner line, as read before.
        character(len=*), intent(in) :: owner
        !> True when this run removed it.
        logical, intent(out) :: taken
        !> '' or the `.break` lock that kept this run from removing it.
        character(len=:), allocatable, intent(out) :: blocker
        !> Set when `.break` cannot be created (a failure of the file system).
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: guard, line, holder, deeper
        integer :: attempt
        logical :: created, ignored
        taken = .false.
        blocker = ''
        guard = path//break_suffix
        do attempt = 1, 3
            call try_create(guard, line, created, error)
            if (allocated(error)) return
            if (created) exit
            holder = read_owner(guard)
            if (len(holder) == 0 .and. .not. file_exists(guard)) cycle
            if (attempt == 3 .or. lock_owner_alive(holder, host_name())) then
                blocker = guard
                return
            end if
            call break_stale(guard, holder, ignored, deeper, error)
            if (allocated(error)) return
            if (len(deeper) > 0) then
                blocker = deeper
                return
            end if
        end do
        if (.not. created) then
            blocker = guard
            return
        end if
        if (read_owner(path) == owner) then
            call remove_file(path)
            taken = .true.
        end if
        call remove_own(guard, line)
    end subroutine break_stale

    !> Remove the files that runs of this host killed while taking a lock of this folder left
    !> (`<lock>.<host>.<pid>`, `<lock>.break.<host>.<pid>`, `<lock>.break.break.<host>.<pid>`,
    !> ..., and `<lock>.stale.<host>.<pid>` of earlier versions), whose process no longer
    !> runs, and break the `.break` locks (`<lock>.break`, `<lock>.break.break`, ...) such a run
    !> left. Files of another host, or of a process that runs (perhaps another run taking the
    !> lock now), are left.
    subroutine remove_dead_files(path)
        !> Path of the lock (held).
        character(len=*), intent(in) :: path
        type(string_t), allocatable :: names(:)
        type(error_t), allocatable :: error
        character(len=:), allocatable :: prefix, rest, host, own, owner, blocker
        integer :: k
        logical :: taken
        host = host_name()
        own = to_str(int(c_getpid()))
        prefix = basename(path)//'.'
        call folder_names(dirname(path), prefix, names)
        do k = 1, size(names)
            rest = names(k)%s(len(prefix) + 1:)
            if (is_break_lock(rest)) then
                ! a `.break` of a run killed as it took a stale lock over
                owner = read_owner(dirname(path)//'/'//names(k)%s)
                if (len(owner) > 0 .and. .not. lock_owner_alive(owner, host)) &
                    call break_stale(dirname(path)//'/'//names(k)%s, owner, taken, blocker, error)
                cycle
            end if
            do while (.not. dead_process(rest))
                if (len(rest) <= 6) exit
                if (rest(1:6) /= 'break.' .and. rest(1:6) /= 'stale.') exit
                rest = rest(7:)
            end do
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
        !> Whether `name` (after '<lock>.') is 'break', 'break.break', ...: a `.break` lock.
        logical function is_break_lock(name)
            character(len=*), intent(in) :: name
            integer :: n
            n = len(break_suffix)
            is_break_lock = .false.
            if (mod(len(name) + 1, n) /= 0) return
            is_break_lock = '.'//name == repeat(break_suffix, (len(name) + 1)/n)
        end function is_break_lock
    end subroutine remove_dead_files

    !> Remove the lock file if this process holds it.
    subroutine lock_release(lock)
        !> The lock.
        type(lock_t), intent(inout) :: lock
        if (.not. lock%held) return
        call remove_own(lock%path, lock%line)
        lock%held = .false.
    end subroutine lock_release

    !> Remove the lock `path` that this process made with the line `line`, if it still holds
    !> that line (it never holds another's, unless one was removed by hand: that is left).
    subroutine remove_own(path, line)
        character(len=*), intent(in) :: path, line
        if (read_owner(path) == line) call remove_file(path)
    end subroutine remove_own

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

    !> Create the lock file `path` with its owner line `line`; `created` is false when it
    !> exists already. The line goes to a file of this process's own (`<path>.<host>.<pid>`),
    !> linked to the lock's name (link(2) fails when the name exists), so that the lock never
    !> exists without its line. This never removes `path`, whoever made it.
    subroutine try_create(path, line, created, error)
        character(len=*), intent(in) :: path
        character(len=:), allocatable, intent(out) :: line
        logical, intent(out) :: created
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: own
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
