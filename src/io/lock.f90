!> One writer per results folder: a lock file `<folder>/.multicor.lock`, independent of HDF5
!> file locking (which is often off on NFS and Lustre).
!>
!> The lock is created with `open(status='new')`, which fails when the file exists (an
!> exclusive create, atomic on a local file system). It holds one line `host pid start-time`
!> naming its owner. A second run on the folder is refused with the owner's line. A lock left
!> by a run that died without removing it (its pid no longer runs on this host) is stale: it is
!> taken over, and the caller gets a warning to print. A lock from another host cannot be
!> checked and is always respected. `lock_release` removes the file; the driver calls it on
!> every way out of a run, errors included.
module io_lock
    use, intrinsic :: iso_c_binding, only: c_char, c_int, c_size_t, c_null_char
    use core_error, only: error_t, make_error
    use core_strings, only: to_str, split_words, string_t, parse_int
    use io_paths, only: file_exists, remove_file
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
        logical :: created
        warning = ''
        lock%path = dir//'/'//lock_name
        do attempt = 1, 2
            call try_create(lock%path, created, error)
            if (allocated(error)) return
            if (created) then
                lock%held = .true.
                return
            end if
            owner = read_owner(lock%path)
            if (attempt == 2) exit
            if (lock_owner_alive(owner, host_name())) exit
            warning = "warning: taking over the stale lock '"//lock%path//"' of a run that no longer "// &
                      'runs (host pid start: '//owner//')'
            call remove_file(lock%path)
        end do
        if (len(owner) == 0) owner = 'unknown'
        call make_error(error, "results folder '"//dir//"' is in use by another run (host pid start: "//owner// &
                        "; lock file '"//lock%path//"'): choose another --output folder, or wait; "// &
                        'remove the lock file only if that run is gone')
    end subroutine lock_acquire

    !> Remove the lock file if this process holds it.
    subroutine lock_release(lock)
        !> The lock.
        type(lock_t), intent(inout) :: lock
        if (.not. lock%held) return
        call remove_file(lock%path)
        lock%held = .false.
    end subroutine lock_release

    !> Whether the owner line `host pid ...` names a process that may still run: always true
    !> for another host (it cannot be checked) or an unreadable line; on this host, true when
    !> /proc/<pid> exists.
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
        alive = file_exists('/proc/'//to_str(pid))
    end function lock_owner_alive

    !> Create the lock file exclusively and write the owner line; `created` is false when
    !> it exists already.
    subroutine try_create(path, created, error)
        character(len=*), intent(in) :: path
        logical, intent(out) :: created
        type(error_t), allocatable, intent(out) :: error
        integer :: unit, ios
        character(len=256) :: msg
        character(len=8) :: date
        character(len=10) :: time
        created = .false.
        open (newunit=unit, file=path, status='new', action='write', iostat=ios, iomsg=msg)
        if (ios /= 0) then
            if (file_exists(path)) return
            call make_error(error, "cannot create the lock file '"//path//"': "//trim(msg))
            return
        end if
        call date_and_time(date, time)
        write (unit, '(a)', iostat=ios) host_name()//' '//to_str(int(c_getpid()))//' '// &
            date(1:4)//'-'//date(5:6)//'-'//date(7:8)//'T'//time(1:2)//':'//time(3:4)//':'//time(5:6)
        close (unit)
        created = .true.
    end subroutine try_create

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
