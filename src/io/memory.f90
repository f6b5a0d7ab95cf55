!> Memory available to a run, read from the Linux kernel's /proc/meminfo (line
!> `MemAvailable: <n> kB`: the memory a new program can use without swapping).
module io_memory
    use core_kinds, only: i8
    implicit none
    private
    public :: available_memory

contains

    !> Bytes of memory available (MemAvailable), or -1 when unknown (no /proc/meminfo, or no
    !> such line: not Linux, or a kernel older than 3.14).
    function available_memory(meminfo) result(bytes)
        !> File to read (default '/proc/meminfo'; another path for tests).
        character(len=*), intent(in), optional :: meminfo
        integer(i8) :: bytes
        character(len=256) :: line
        character(len=:), allocatable :: path
        integer :: unit, ios, colon
        integer(i8) :: kib
        bytes = -1
        path = '/proc/meminfo'
        if (present(meminfo)) path = meminfo
        open (newunit=unit, file=path, status='old', action='read', iostat=ios)
        if (ios /= 0) return
        do
            read (unit, '(a)', iostat=ios) line
            if (ios /= 0) exit
            if (index(line, 'MemAvailable:') /= 1) cycle
            colon = index(line, ':')
            line = line(colon + 1:)
            colon = index(line, 'kB')
            if (colon > 0) line = line(:colon - 1)
            read (line, *, iostat=ios) kib
            if (ios == 0 .and. kib >= 0) bytes = 1024_i8*kib
            exit
        end do
        close (unit)
    end function available_memory
end module io_memory
