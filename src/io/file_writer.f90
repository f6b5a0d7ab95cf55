!> A file written with every write error reported: the text files of a run (the XDMF file,
!> the folder's lock) and the copy of a results file.
!>
!> libgfortran does not report some write errors: what a formatted or stream unit keeps in
!> its buffer and writes at a FLUSH or CLOSE fails without an error (to /dev/full, a full
!> disk, a file size limit: iostat 0 from WRITE, FLUSH and CLOSE), which left a truncated or
!> empty `.xdmf` and exit code 0. The writer calls write(2), fsync(2) and close(2) itself
!> (src/io/files_c.c): it keeps the first failure and `close` reports it with the system's
!> reason ("cannot write the XDMF file 'r/a.xdmf.partial': No space left on device").
!> Bytes are gathered in a 64 KiB buffer, written when it is full and at the close.
module io_file_writer
    use, intrinsic :: iso_c_binding, only: c_char, c_int, c_long, c_null_char
    use core_error, only: error_t, make_error
    implicit none
    private
    public :: file_writer_t, system_error_text, errno_exists

    !> Bytes gathered before a write(2).
    integer, parameter :: buffer_size = 65536

    !> A file open for writing.
    type :: file_writer_t
        !> File descriptor (-1 when closed).
        integer(c_int), private :: fd = -1
        !> errno of the first failure (0: none).
        integer, private :: status = 0
        !> Path of the file.
        character(len=:), allocatable, private :: path
        !> What the file is, for messages ('the XDMF file').
        character(len=:), allocatable, private :: what
        !> Bytes not written yet.
        character(len=:), allocatable, private :: buffer
        !> Bytes used in `buffer`.
        integer, private :: fill = 0
    contains
        !> Create (or truncate) the file.
        procedure :: create => writer_create
        !> Append bytes.
        procedure :: write => writer_write
        !> Append a line (the text and a newline).
        procedure :: write_line => writer_write_line
        !> Write what is left, sync and close; report the first failure.
        procedure :: close => writer_close
        !> Close without reporting anything (a file given up).
        procedure :: discard => writer_discard
        !> Whether the file is open.
        procedure :: is_open => writer_is_open
    end type file_writer_t

    interface
        function c_create(path, exclusive) bind(C, name='multicor_file_create') result(fd)
            import :: c_char, c_int
            character(kind=c_char), intent(in) :: path(*)
            integer(c_int), value :: exclusive
            integer(c_int) :: fd
        end function c_create
        function c_write(fd, buf, n) bind(C, name='multicor_file_write') result(err)
            import :: c_char, c_int, c_long
            integer(c_int), value :: fd
            character(kind=c_char), intent(in) :: buf(*)
            integer(c_long), value :: n
            integer(c_int) :: err
        end function c_write
        function c_close(fd) bind(C, name='multicor_file_close') result(err)
            import :: c_int
            integer(c_int), value :: fd
            integer(c_int) :: err
        end function c_close
        subroutine c_discard(fd) bind(C, name='multicor_file_discard')
            import :: c_int
            integer(c_int), value :: fd
        end subroutine c_discard
        subroutine c_errno_text(err, buf, n) bind(C, name='multicor_errno_text')
            import :: c_char, c_int, c_long
            integer(c_int), value :: err
            character(kind=c_char), intent(out) :: buf(*)
            integer(c_long), value :: n
        end subroutine c_errno_text
        function c_eexist() bind(C, name='multicor_eexist') result(code)
            import :: c_int
            integer(c_int) :: code
        end function c_eexist
    end interface

contains

    !> Create `path` for writing: truncated if it exists, or, when `exclusive`, an error
    !> if it exists (`errno_exists(code)` is then true).
    subroutine writer_create(self, path, what, error, exclusive, code)
        !> The writer (closed).
        class(file_writer_t), intent(inout) :: self
        !> File to write.
        character(len=*), intent(in) :: path
        !> What the file is, for messages ('the XDMF file'; '': the path alone).
        character(len=*), intent(in) :: what
        !> Set when the file cannot be created.
        type(error_t), allocatable, intent(out) :: error
        !> The file must not exist (default: false).
        logical, intent(in), optional :: exclusive
        !> errno of the failure (0: created).
        integer, intent(out), optional :: code
        integer(c_int) :: excl
        if (self%fd >= 0) call c_discard(self%fd)
        excl = 0
        if (present(exclusive)) then
            if (exclusive) excl = 1
        end if
        self%path = path
        self%what = what
        self%status = 0
        self%fill = 0
        if (.not. allocated(self%buffer)) allocate (character(len=buffer_size) :: self%buffer)
        self%fd = c_create(path//c_null_char, excl)
        if (present(code)) code = 0
        if (self%fd < 0) then
            if (present(code)) code = -int(self%fd)
            call make_error(error, 'cannot create '//named(what, path)//': '//system_error_text(-int(self%fd)))
            self%fd = -1
        end if
    end subroutine writer_create

    !> Append `bytes` (nothing once a write has failed: `close` reports it).
    subroutine writer_write(self, bytes)
        !> The writer (open).
        class(file_writer_t), intent(inout) :: self
        !> The bytes.
        character(len=*), intent(in) :: bytes
        if (self%fd < 0 .or. self%status /= 0) return
        if (self%fill + len(bytes) > buffer_size) then
            call flush_buffer(self)
            if (self%status /= 0) return
        end if
        if (len(bytes) >= buffer_size) then
            self%status = int(c_write(self%fd, bytes, int(len(bytes), c_long)))
            return
        end if
        self%buffer(self%fill + 1:self%fill + len(bytes)) = bytes
        self%fill = self%fill + len(bytes)
    end subroutine writer_write

    !> Append `line` and a newline.
    subroutine writer_write_line(self, line)
        !> The writer (open).
        class(file_writer_t), intent(inout) :: self
        !> The line, without its newline.
        character(len=*), intent(in) :: line
        call self%write(line//new_line('a'))
    end subroutine writer_write_line

    !> Write the buffer, sync the file to its device and close it; an error names the file
    !> and the system's reason for the first failure.
    subroutine writer_close(self, error, code)
        !> The writer.
        class(file_writer_t), intent(inout) :: self
        !> Set when a write, the sync or the close failed.
        type(error_t), allocatable, intent(out) :: error
        !> errno of the first failure (0: none).
        integer, intent(out), optional :: code
        integer :: status
        if (present(code)) code = 0
        if (self%fd < 0) return
        call flush_buffer(self)
        status = int(c_close(self%fd))
        self%fd = -1
        if (self%status == 0) self%status = status
        if (present(code)) code = self%status
        if (self%status /= 0) call make_error(error, 'cannot write '//named(self%what, self%path)//': '// &
                                              system_error_text(self%status))
    end subroutine writer_close

    !> Close the file, ignoring any failure.
    subroutine writer_discard(self)
        !> The writer.
        class(file_writer_t), intent(inout) :: self
        if (self%fd < 0) return
        call c_discard(self%fd)
        self%fd = -1
    end subroutine writer_discard

    !> Whether the file is open.
    pure logical function writer_is_open(self)
        !> The writer.
        class(file_writer_t), intent(in) :: self
        writer_is_open = self%fd >= 0
    end function writer_is_open

    !> Write the gathered bytes.
    subroutine flush_buffer(self)
        type(file_writer_t), intent(inout) :: self
        if (self%fill > 0 .and. self%status == 0) &
            self%status = int(c_write(self%fd, self%buffer, int(self%fill, c_long)))
        self%fill = 0
    end subroutine flush_buffer

    !> "the XDMF file 'a.xdmf'", or "'a.xdmf'" when `what` is ''.
    pure function named(what, path) result(text)
        character(len=*), intent(in) :: what, path
        character(len=:), allocatable :: text
        if (len(what) > 0) then
            text = what//" '"//path//"'"
        else
            text = "'"//path//"'"
        end if
    end function named

    !> The system's text for an errno value ('No space left on device').
    function system_error_text(code) result(text)
        !> The errno value.
        integer, intent(in) :: code
        !> Its text.
        character(len=:), allocatable :: text
        character(kind=c_char, len=256) :: buf
        integer :: n
        buf = ''
        call c_errno_text(int(code, c_int), buf, int(len(buf), c_long))
        n = index(buf, c_null_char) - 1
        if (n < 0) n = len_trim(buf)
        text = buf(:n)
    end function system_error_text

    !> Whether an errno value says the file exists (EEXIST).
    logical function errno_exists(code)
        !> The errno value.
        integer, intent(in) :: code
        errno_exists = code == int(c_eexist())
    end function errno_exists
end module io_file_writer
