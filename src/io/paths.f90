!> File-system helpers: file name parts, directory creation and listing, file existence, copy
!> and removal.
module io_paths
    use, intrinsic :: iso_c_binding, only: c_char, c_int, c_long, c_null_char
    use, intrinsic :: iso_fortran_env, only: int64
    use core_error, only: error_t, make_error
    use core_strings, only: string_t
    use io_file_writer, only: file_writer_t, system_error_text
    implicit none
    private
    public :: basename, dirname, stem, mkdir_p, remove_empty_folders, file_exists, remove_file, rename_file, copy_file
    public :: link_or_copy_file
    public :: read_file_text, folder_names

    interface
        function c_make_dir(path) bind(C, name='multicor_make_dir') result(err)
            import :: c_char, c_int
            character(kind=c_char), intent(in) :: path(*)
            integer(c_int) :: err
        end function c_make_dir
        function c_rmdir(path) bind(C, name='rmdir') result(rc)
            import :: c_char, c_int
            character(kind=c_char), intent(in) :: path(*)
            integer(c_int) :: rc
        end function c_rmdir
        function c_rename(old, new) bind(C, name='multicor_rename') result(err)
            import :: c_char, c_int
            character(kind=c_char), intent(in) :: old(*), new(*)
            integer(c_int) :: err
        end function c_rename
        function c_is_dir(path) bind(C, name='multicor_is_dir') result(yes)
            import :: c_char, c_int
            character(kind=c_char), intent(in) :: path(*)
            integer(c_int) :: yes
        end function c_is_dir
        function c_folder_names(path, prefix, buf, n) bind(C, name='multicor_folder_names') result(used)
            import :: c_char, c_long
            character(kind=c_char), intent(in) :: path(*), prefix(*)
            character(kind=c_char), intent(out) :: buf(*)
            integer(c_long), value :: n
            integer(c_long) :: used
        end function c_folder_names
        function c_link(old, new) bind(C, name='link') result(rc)
            import :: c_char, c_int
            character(kind=c_char), intent(in) :: old(*), new(*)
            integer(c_int) :: rc
        end function c_link
    end interface

contains

    !> Last component of a path ('input/cantilever.dat' -> 'cantilever.dat').
    pure function basename(path) result(name)
        !> A file path.
        character(len=*), intent(in) :: path
        character(len=:), allocatable :: name
        integer :: i
        i = index(path, '/', back=.true.)
        name = path(i + 1:)
    end function basename

    !> Folder of a path ('results/a/checkpoint.h5' -> 'results/a', 'a.h5' -> '.', '/a.h5' -> '/').
    pure function dirname(path) result(name)
        !> A file path.
        character(len=*), intent(in) :: path
        character(len=:), allocatable :: name
        integer :: i
        i = index(path, '/', back=.true.)
        if (i == 0) then
            name = '.'
        else if (i == 1) then
            name = '/'
        else
            name = path(:i - 1)
        end if
    end function dirname

    !> File name without folder and without its last extension ('input/a.dat' -> 'a').
    pure function stem(path) result(name)
        !> A file path.
        character(len=*), intent(in) :: path
        character(len=:), allocatable :: name
        integer :: i
        name = basename(path)
        i = index(name, '.', back=.true.)
        if (i > 1) name = name(:i - 1)
    end function stem

    !> True if a file (or folder) exists.
    logical function file_exists(path)
        !> A path.
        character(len=*), intent(in) :: path
        inquire (file=path, exist=file_exists)
    end function file_exists

    !> Create a folder and its parents (like mkdir -p).
    subroutine mkdir_p(path, error, created)
        !> Folder to create.
        character(len=*), intent(in) :: path
        !> Set if a folder could not be created, with the system's reason ('Permission
        !> denied'), or the file in the way of a folder.
        type(error_t), allocatable, intent(out) :: error
        !> The outermost folder this call created ('' when `path` existed already), for
        !> `remove_empty_folders` to undo the call.
        character(len=:), allocatable, intent(out), optional :: created
        integer :: i
        integer(c_int) :: rc
        character(len=:), allocatable :: parent
        if (present(created)) created = ''
        do i = 2, len_trim(path) + 1
            if (i <= len_trim(path)) then
                if (path(i:i) /= '/') cycle
            end if
            if (file_exists(path(:i - 1))) cycle
            rc = c_make_dir(path(:i - 1)//c_null_char)
            if (rc /= 0) then
                if (file_exists(path(:i - 1))) cycle
                parent = dirname(path(:i - 1))
                if (file_exists(parent) .and. c_is_dir(parent//c_null_char) == 0) then
                    ! ENOTDIR ('Not a directory') does not say which part of the path
                    call make_error(error, "cannot create folder '"//path(:i - 1)//"': '"//parent// &
                                    "' is a file, not a folder")
                else
                    call make_error(error, "cannot create folder '"//path(:i - 1)//"': "//system_error_text(int(rc)))
                end if
                return
            end if
            if (present(created)) then
                if (rc == 0 .and. len(created) == 0) created = path(:i - 1)
            end if
        end do
        ! A file of that name is in the way (not a folder): the lock file or the results
        ! inside it would fail with a less telling 'Not a directory'.
        if (c_is_dir(trim(path)//c_null_char) == 0) &
            call make_error(error, "cannot use '"//trim(path)//"' as the results folder: it exists and is not a "// &
                            'folder (give --output another name, or move that file)')
    end subroutine mkdir_p

    !> Undo `mkdir_p` where nothing was put in the folders it created: remove `path` and its
    !> parents up to `created` (the outermost folder that call created) while they are empty.
    !> Folders that hold anything are kept (rmdir refuses them), as is everything above `created`.
    subroutine remove_empty_folders(path, created)
        !> The folder given to `mkdir_p`.
        character(len=*), intent(in) :: path
        !> What `mkdir_p` returned as `created` ('': nothing to remove).
        character(len=*), intent(in) :: created
        integer :: i
        character(len=:), allocatable :: folder
        if (len(created) == 0) return
        folder = trim(path)
        do while (len(folder) > 1 .and. folder(len(folder):) == '/')
            folder = folder(:len(folder) - 1)
        end do
        do while (len(folder) >= len(created))
            if (c_rmdir(folder//c_null_char) /= 0) return
            if (folder == created) return
            i = index(folder, '/', back=.true.)
            if (i <= 1) return
            folder = folder(:i - 1)
        end do
    end subroutine remove_empty_folders

    !> The names of the entries of folder `path` that begin with `prefix` (any order; none
    !> when the folder cannot be read).
    subroutine folder_names(path, prefix, names)
        !> The folder.
        character(len=*), intent(in) :: path
        !> Beginning of the names wanted ('' for all but '.' and '..').
        character(len=*), intent(in) :: prefix
        !> The names.
        type(string_t), allocatable, intent(out) :: names(:)
        character(kind=c_char, len=:), allocatable :: buf
        integer(c_long) :: used
        integer :: first, last, attempt
        names = [string_t ::]
        used = 256
        ! a folder that grows between two calls needs a third
        do attempt = 1, 5
            if (allocated(buf)) deallocate (buf)
            allocate (character(kind=c_char, len=max(int(used), 1)) :: buf)
            used = c_folder_names(path//c_null_char, prefix//c_null_char, buf, int(len(buf), c_long))
            if (used < 0) return
            if (used <= len(buf)) exit
        end do
        if (used > len(buf)) return
        first = 1
        do while (first <= used)
            last = first + index(buf(first:used), c_null_char) - 2
            names = [names, string_t(buf(first:last))]
            first = last + 2
        end do
    end subroutine folder_names

    !> Delete a file if it exists.
    subroutine remove_file(path)
        !> File to delete.
        character(len=*), intent(in) :: path
        integer :: unit, ios
        if (.not. file_exists(path)) return
        open (newunit=unit, file=path, status='old', iostat=ios)
        if (ios == 0) close (unit, status='delete', iostat=ios)
    end subroutine remove_file

    !> Rename a file, replacing the target if it exists.
    subroutine rename_file(old, new, error)
        !> Current name.
        character(len=*), intent(in) :: old
        !> New name.
        character(len=*), intent(in) :: new
        !> Set if the rename failed.
        type(error_t), allocatable, intent(out) :: error
        integer(c_int) :: err
        err = c_rename(old//c_null_char, new//c_null_char)
        if (err /= 0) call make_error(error, "cannot rename '"//old//"' to '"//new//"': "//system_error_text(int(err)))
    end subroutine rename_file
    !> Copy a file byte for byte (the target is replaced; on failure it is removed).
    subroutine copy_file(old, new, error)
        !> File to copy.
        character(len=*), intent(in) :: old
        !> Name of the copy.
        character(len=*), intent(in) :: new
        !> Set if the file cannot be read or the copy written.
        type(error_t), allocatable, intent(out) :: error
        integer, parameter :: block = 1048576
        character(len=:), allocatable :: buf
        character(len=256) :: msg
        type(file_writer_t) :: dst
        integer :: src, ios, n
        integer(int64) :: size_bytes, pos
        open (newunit=src, file=old, access='stream', form='unformatted', status='old', &
              action='read', iostat=ios, iomsg=msg)
        if (ios /= 0) then
            call make_error(error, "cannot read '"//old//"': "//trim(msg))
            return
        end if
        inquire (unit=src, size=size_bytes)
        ! written by io_file_writer: a Fortran unit's last buffered bytes could fail unreported
        call dst%create(new, '', error)
        if (allocated(error)) then
            close (src)
            return
        end if
        allocate (character(len=block) :: buf)
        pos = 0
        ios = 0
        do while (pos < size_bytes .and. ios == 0)
            n = int(min(int(block, int64), size_bytes - pos))
            read (src, iostat=ios, iomsg=msg) buf(:n)
            if (ios == 0) call dst%write(buf(:n))
            pos = pos + n
        end do
        close (src)
        if (ios /= 0) then
            call dst%discard()
            call remove_file(new)
            call make_error(error, "cannot copy '"//old//"' to '"//new//"': "//trim(msg))
            return
        end if
        call dst%close(error)
        if (allocated(error)) then
            call remove_file(new)
            error%message = "cannot copy '"//old//"' to '"//new//"': "//error%message
        end if
    end subroutine copy_file

    !> Give a file a second name `new` (replaced if it exists): a hard link, or a copy where
    !> the file system has no hard links. Renaming another file onto `old` afterwards leaves
    !> `new` with the earlier content.
    subroutine link_or_copy_file(old, new, error)
        !> Existing file.
        character(len=*), intent(in) :: old
        !> Second name.
        character(len=*), intent(in) :: new
        !> Set if neither a link nor a copy could be made.
        type(error_t), allocatable, intent(out) :: error
        call remove_file(new)
        if (c_link(old//c_null_char, new//c_null_char) == 0) return
        call copy_file(old, new, error)
    end subroutine link_or_copy_file
    !> The whole content of a file, its bytes as characters (for hashing the inputs of a run).
    subroutine read_file_text(path, text, error)
        !> File to read.
        character(len=*), intent(in) :: path
        !> Its content.
        character(len=:), allocatable, intent(out) :: text
        !> Set if the file cannot be read (or holds 2 GiB or more).
        type(error_t), allocatable, intent(out) :: error
        character(len=256) :: msg
        integer :: unit, ios
        integer(int64) :: size_bytes
        open (newunit=unit, file=path, access='stream', form='unformatted', status='old', &
              action='read', iostat=ios, iomsg=msg)
        if (ios /= 0) then
            call make_error(error, "cannot read '"//path//"': "//trim(msg))
            return
        end if
        inquire (unit=unit, size=size_bytes)
        if (size_bytes < 0 .or. size_bytes > huge(0)) then
            close (unit)
            call make_error(error, "cannot read '"//path//"': size unknown or 2 GiB or more")
            return
        end if
        allocate (character(len=int(size_bytes)) :: text)
        ios = 0
        if (size_bytes > 0) read (unit, iostat=ios, iomsg=msg) text
        close (unit)
        if (ios /= 0) call make_error(error, "cannot read '"//path//"': "//trim(msg))
    end subroutine read_file_text
end module io_paths
