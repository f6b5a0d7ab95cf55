!> The only module that calls HDF5: a small file object with groups, attributes, datasets and
!> extendible time series, every failure returned as an `error_t`.
!>
!> Layout conventions:
!> - Paths are absolute or relative to the root ('/fem/time' and 'fem/time' are the same);
!>   missing intermediate groups are created on the fly.
!> - Arrays are written in Fortran order: a Fortran array of shape (3, n) appears in h5py /
!>   C order with shape (n, 3).
!> - Time series are chunked datasets whose LAST Fortran dimension is unlimited: records of
!>   shape (3, n) build a Fortran array (3, n, n_records), i.e. (n_records, n, 3) in h5py.
!>   `append` adds one record; `append_chunk` adds any number at once (variable-length
!>   data such as contact lists, or buffered per-step values). Series hold reals, or
!>   integers for scalar records (`create_int_series`).
!> - Reals are stored as IEEE 64-bit little endian, integers as 32-bit little endian, string
!>   attributes as variable-length UTF-8 (h5py returns them as `str`).
!>
!> The HDF5 library is opened on first use (checked through the validity of a predefined
!> type id, so no module state is kept) and never closed here: `h5close_f` would close every
!> file of the process. Its exit handler is switched off (`h5dont_atexit_f`): after a failed
!> write (full disk) HDF5 cannot close the file, and its exit handler then crashed trying
!> again; every file written is closed explicitly, so nothing is lost. Automatic printing of
!> the HDF5 error stack is switched off: errors are reported through `error_t` only.
!>
!> Crash safety: files are created with the file-space strategy NONE (space freed while the
!> file is open is never reused) and `flush` writes everything HDF5 buffers; a writer killed
!> between two flushes leaves the file as it was at the first one (doc/decisions.md).
module io_hdf5_file
    use, intrinsic :: iso_c_binding, only: c_ptr, c_char, c_size_t, c_null_char, c_null_ptr, &
                                                                              c_loc, c_f_pointer, c_associated, &
                                                                              c_int, c_bool, c_int64_t, c_long_long
    use core_kinds, only: wp
    use core_error, only: error_t, make_error, make_internal_error
    use hdf5, only: hid_t, hsize_t, size_t, h5open_f, h5dont_atexit_f, h5eset_auto_f, h5iis_valid_f, &
                    h5iget_type_f, h5i_dataset_f, h5i_dataspace_f, h5i_datatype_f, h5i_attr_f, h5i_group_f, &
                    h5i_genprop_lst_f, h5i_file_f, h5fcreate_f, h5fopen_f, h5fclose_f, h5f_acc_trunc_f, &
                    h5f_acc_rdonly_f, h5fflush_f, h5f_scope_global_f, h5f_libver_v18_f, &
                    h5f_libver_latest_f, h5pcreate_f, h5pclose_f, &
                    h5pset_libver_bounds_f, h5pset_create_inter_group_f, h5pset_chunk_f, &
                    h5p_file_access_f, h5p_file_create_f, h5p_link_create_f, h5p_dataset_create_f, h5gcreate_f, h5gclose_f, &
                    h5lexists_f, h5oopen_f, h5oclose_f, h5screate_f, h5screate_simple_f, h5sclose_f, &
                    h5s_scalar_f, h5s_unlimited_f, h5s_select_set_f, h5sselect_hyperslab_f, &
                    h5sget_simple_extent_ndims_f, h5sget_simple_extent_dims_f, h5acreate_f, h5aopen_f, &
                    h5aclose_f, h5awrite_f, h5aread_f, h5aexists_f, h5adelete_f, h5aget_space_f, &
                    h5aget_type_f, h5dcreate_f, h5dopen_f, h5dclose_f, h5dwrite_f, h5dread_f, &
                    h5dget_space_f, h5dget_type_f, h5dset_extent_f, h5tcopy_f, h5tclose_f, h5tset_size_f, &
                    h5tset_strpad_f, h5tset_cset_f, h5tget_class_f, &
                    h5t_native_double, h5t_native_integer, h5t_ieee_f64le, h5t_std_i32le, &
                    h5t_str_nullterm_f, h5t_cset_utf8_f, h5t_float_f, h5t_integer_f, &
                    h5t_string_f, h5t_c_s1, h5tis_variable_str_f, h5dvlen_reclaim_f, h5p_default_f, &
                    h5f_acc_rdwr_f, h5gn_members_f, h5gget_obj_info_idx_f, h5g_group_f, h5g_dataset_f, &
                    h5ldelete_f
    implicit none
    private
    public :: h5_file_t

    interface
        !> Length of a null-terminated C string (C library).
        pure function c_strlen(s) bind(c, name='strlen') result(n)
            import :: c_ptr, c_size_t
            type(c_ptr), value, intent(in) :: s
            integer(c_size_t) :: n
        end function c_strlen
        !> H5Pset_file_space_strategy of the C library (no Fortran wrapper in HDF5 1.10).
        integer(c_int) function c_h5pset_file_space_strategy(plist, strategy, persist, &
                                                             threshold) &
            bind(c, name='H5Pset_file_space_strategy')
            import :: c_int, c_bool, c_int64_t, c_long_long
            !> File creation property list (hid_t is int64_t in HDF5 1.10).
            integer(c_int64_t), value, intent(in) :: plist
            integer(c_int), value, intent(in) :: strategy
            logical(c_bool), value, intent(in) :: persist
            !> hsize_t (unsigned long long).
            integer(c_long_long), value, intent(in) :: threshold
        end function c_h5pset_file_space_strategy
    end interface

    !> Value of H5F_FSPACE_STRATEGY_NONE (every allocation at the end of the file, freed space never
    !> reused while the file is open; see file_create).
    integer(c_int), parameter :: fspace_strategy_none = 3

    !> Target size of one chunk of a time series [bytes].
    integer, parameter :: chunk_bytes = 65536
    !> Largest number of records in one chunk of a time series.
    integer, parameter :: max_chunk_records = 1024
    !> H5T_VARIABLE, the size of a variable-length string type: (size_t)(-1) in C; the
    !> Fortran API of HDF5 1.10 does not export it.
    integer(size_t), parameter :: h5t_variable = -1_size_t

    !> An HDF5 file opened for writing (create) or reading (open).
    type :: h5_file_t
        !> HDF5 file identifier (-1 when closed).
        integer(hid_t), private :: id = -1
        !> Whether the file was opened for writing.
        logical, private :: writable = .false.
        !> File name, for error messages.
        character(len=:), allocatable :: path
    contains
        !> Create a file (an existing one is replaced).
        procedure :: create => file_create
        !> Open an existing file, read-only or for writing.
        procedure :: open => file_open
        !> Close the file (nothing when it is not open).
        procedure :: close => file_close
        !> Flush every buffer of the file to the operating system.
        procedure :: flush => file_flush
        !> True while a file is open.
        procedure :: is_open => file_is_open
        !> True when a group, dataset or attribute path exists.
        procedure :: exists => file_exists
        !> Create a group (and its missing parents).
        procedure :: create_group => file_create_group
        procedure, private :: write_attr_string, write_attr_real, write_attr_int, &
            write_attr_real_1d
        !> Write (or overwrite) an attribute on a group, a dataset or the root ('/').
        generic :: write_attribute => write_attr_string, write_attr_real, write_attr_int, &
            write_attr_real_1d
        procedure, private :: read_attr_string, read_attr_real, read_attr_int, read_attr_real_1d
        !> Read an attribute of a group, a dataset or the root ('/').
        generic :: read_attribute => read_attr_string, read_attr_real, read_attr_int, &
            read_attr_real_1d
        procedure, private :: write_real_1d, write_real_2d, write_real_3d, write_int_1d, &
            write_int_2d
        !> Write a new fixed-size dataset (an existing one is an error).
        generic :: write_dataset => write_real_1d, write_real_2d, write_real_3d, write_int_1d, &
            write_int_2d
        procedure, private :: read_real_1d, read_real_2d, read_real_3d, read_int_1d, read_int_2d
        !> Read a whole dataset into an array allocated to its shape.
        generic :: read_dataset => read_real_1d, read_real_2d, read_real_3d, read_int_1d, &
            read_int_2d
        !> Shape of a dataset, in Fortran order.
        procedure :: dataset_shape => file_dataset_shape
        !> Paths of every dataset in the file and their number of records.
        procedure :: list_datasets => file_list_datasets
        !> Delete a dataset or group.
        procedure :: delete => file_delete
        !> Cut or extend a series to a number of records.
        procedure :: resize_series => file_resize_series
        !> Create an extendible real series of scalar, 1-D or 2-D records.
        procedure :: create_series => file_create_series
        !> Create an extendible integer series of scalar records.
        procedure :: create_int_series => file_create_int_series
        procedure, private :: append_0d, append_1d, append_2d
        !> Append one record (scalar, 1-D or 2-D) at the end of a series.
        generic :: append => append_0d, append_1d, append_2d
        procedure, private :: append_chunk_real, append_chunk_real_2d, append_chunk_int
        !> Append a variable number of records at once (possibly none): reals to a scalar
        !> series, columns of a 2-D array to a series of 1-D records, integers to an
        !> integer series.
        generic :: append_chunk => append_chunk_real, append_chunk_real_2d, append_chunk_int
        procedure, private :: new_dataset, open_dataset, open_attribute_for_write, &
            open_attribute_for_read, append_record, extend_series
    end type h5_file_t

contains

    !> Create (truncate) a file for writing.
    subroutine file_create(self, path, error)
        !> The file object; must not be open.
        class(h5_file_t), intent(inout) :: self
        !> File name (its folder must exist).
        character(len=*), intent(in) :: path
        !> Set when the library cannot start or the file cannot be created.
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: fapl, fcpl
        integer :: hdferr
        if (self%is_open()) then
            call make_error(error, "HDF5: cannot create '"//path//"': this object still has '" &
                            //self%path//"' open")
            return
        end if
        call ensure_library(error)
        if (allocated(error)) return
        fapl = -1
        fcpl = -1
        self%path = path
        ops: block
            ! The 1.8 file format allows attributes larger than 64 KiB (dense storage).
            call h5pcreate_f(h5p_file_access_f, fapl, hdferr)
            if (hdferr < 0) exit ops
            call h5pset_libver_bounds_f(fapl, h5f_libver_v18_f, h5f_libver_latest_f, hdferr)
            if (hdferr < 0) exit ops
            ! Space freed while the file is open is never reused: what the last flush wrote is
            ! never overwritten by later data, so a killed writer leaves the file as it was at
            ! its last flush (doc/decisions.md).
            call h5pcreate_f(h5p_file_create_f, fcpl, hdferr)
            if (hdferr < 0) exit ops
            hdferr = int(c_h5pset_file_space_strategy(int(fcpl, c_int64_t), fspace_strategy_none, &
                                                      .false._c_bool, 1_c_long_long))
            if (hdferr < 0) exit ops
            call h5fcreate_f(path, h5f_acc_trunc_f, self%id, hdferr, creation_prp=fcpl, &
                             access_prp=fapl)
        end block ops
        call release(fcpl)
        call release(fapl)
        if (hdferr < 0) then
            self%id = -1
            call make_error(error, "HDF5: cannot create file '"//path// &
                            "' (does its folder exist, is it writable?)")
            return
        end if
        self%writable = .true.
    end subroutine file_create

    !> Open an existing file for reading (or, with `writable`, for reading and writing).
    subroutine file_open(self, path, error, writable)
        !> The file object; must not be open.
        class(h5_file_t), intent(inout) :: self
        !> File name.
        character(len=*), intent(in) :: path
        !> Set when the file is missing or is not an HDF5 file.
        type(error_t), allocatable, intent(out) :: error
        !> Open for writing too (default: read only).
        logical, intent(in), optional :: writable
        integer :: hdferr
        logical :: rw
        if (self%is_open()) then
            call make_error(error, "HDF5: cannot open '"//path//"': this object still has '" &
                            //self%path//"' open")
            return
        end if
        call ensure_library(error)
        if (allocated(error)) return
        self%path = path
        rw = .false.
        if (present(writable)) rw = writable
        if (rw) then
            call h5fopen_f(path, h5f_acc_rdwr_f, self%id, hdferr)
        else
            call h5fopen_f(path, h5f_acc_rdonly_f, self%id, hdferr)
        end if
        if (hdferr < 0) then
            self%id = -1
            if (rw) then
                ! HDF5 1.10 refuses a file whose writer was killed (its superblock still says
                ! open for writing) until `h5clear -s` resets that mark.
                call make_error(error, "HDF5: cannot open file '"//path//"' for writing "// &
                                "(missing, not an HDF5 file, read-only, or left open by a killed "// &
                                "writer: then run 'h5clear -s "//path//"' first)")
            else
                call make_error(error, "HDF5: cannot open file '"//path// &
                                "' for reading (missing, or not an HDF5 file)")
            end if
            return
        end if
        self%writable = rw
    end subroutine file_open

    !> Close the file (no-op when it is not open).
    subroutine file_close(self, error)
        !> The file object.
        class(h5_file_t), intent(inout) :: self
        !> Set when HDF5 cannot flush and close the file.
        type(error_t), allocatable, intent(out) :: error
        integer :: hdferr
        if (.not. self%is_open()) return
        call h5fclose_f(self%id, hdferr)
        self%id = -1
        self%writable = .false.
        if (hdferr < 0) call make_error(error, "HDF5: cannot close file '"//self%path//"'")
    end subroutine file_close

    !> Write everything HDF5 holds in memory for this file (raw data, metadata, superblock)
    !> to the operating system: after a flush the file on disk is complete and readable as it
    !> stands, even if the process is killed before the next flush (doc/decisions.md).
    subroutine file_flush(self, error)
        !> A file open for writing.
        class(h5_file_t), intent(inout) :: self
        !> Set when the data cannot be written (e.g. the disk is full).
        type(error_t), allocatable, intent(out) :: error
        integer :: hdferr
        call require_writable(self, '(flush)', error)
        if (allocated(error)) return
        call h5fflush_f(self%id, h5f_scope_global_f, hdferr)
        if (hdferr < 0) call make_error(error, "HDF5: cannot write to file '"//self%path// &
                                        "' (disk full, quota or file size limit exceeded?)")
    end subroutine file_flush

    !> Whether a file is open.
    pure logical function file_is_open(self)
        !> The file object.
        class(h5_file_t), intent(in) :: self
        file_is_open = self%id > 0
    end function file_is_open

    !> Whether a group or dataset exists at `path` ('/' always exists).
    logical function file_exists(self, path)
        !> An open file.
        class(h5_file_t), intent(in) :: self
        !> Object path.
        character(len=*), intent(in) :: path
        integer :: i, hdferr
        logical :: found
        file_exists = .false.
        if (.not. self%is_open()) return
        file_exists = .true.
        ! Check each prefix: h5lexists fails when an intermediate group is missing.
        do i = 2, len(path) + 1
            if (i <= len(path)) then
                if (path(i:i) /= '/') cycle
            end if
            if (len_trim(path(:i - 1)) == 0 .or. path(:i - 1) == '/') cycle
            call h5lexists_f(self%id, path(:i - 1), found, hdferr)
            if (hdferr < 0 .or. .not. found) then
                file_exists = .false.
                return
            end if
        end do
    end function file_exists

    !> Create a group and any missing parent groups; an existing group is left as it is.
    subroutine file_create_group(self, path, error)
        !> A file open for writing.
        class(h5_file_t), intent(inout) :: self
        !> Group path, e.g. '/fem/mesh'.
        character(len=*), intent(in) :: path
        !> Set when the group cannot be created.
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: lcpl, group
        integer :: hdferr
        call require_writable(self, path, error)
        if (allocated(error)) return
        if (self%exists(path)) return
        lcpl = -1
        group = -1
        ops: block
            call link_create_plist(lcpl, hdferr)
            if (hdferr < 0) exit ops
            call h5gcreate_f(self%id, path, group, hdferr, lcpl_id=lcpl)
        end block ops
        call release(group)
        call release(lcpl)
        if (hdferr < 0) call make_error(error, "HDF5: cannot create group '"//path//"' in '" &
                                        //self%path//"'")
    end subroutine file_create_group

    ! ---------------------------------------------------------------------------------------
    ! Attributes
    ! ---------------------------------------------------------------------------------------

    !> Write a string attribute (variable-length UTF-8: h5py reads it as `str`).
    subroutine write_attr_string(self, object, name, value, error)
        !> A file open for writing.
        class(h5_file_t), intent(inout) :: self
        !> Path of the group or dataset carrying the attribute ('/' for the root).
        character(len=*), intent(in) :: object
        !> Attribute name.
        character(len=*), intent(in) :: name
        !> Value (may be empty).
        character(len=*), intent(in) :: value
        !> Set on failure.
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: stype, space, attr
        character(kind=c_char), allocatable, target :: chars(:)
        type(c_ptr), target :: cstring
        type(c_ptr) :: buf
        integer :: hdferr, i
        ! A null-terminated C string and a pointer to it: HDF5's representation of one
        ! variable-length string in memory.
        allocate (chars(len(value) + 1))
        do i = 1, len(value)
            chars(i) = value(i:i)
        end do
        chars(len(value) + 1) = c_null_char
        cstring = c_loc(chars)
        buf = c_loc(cstring)
        stype = -1
        space = -1
        attr = -1
        ops: block
            call vl_string_type(stype, hdferr)
            if (hdferr < 0) exit ops
            call h5screate_f(h5s_scalar_f, space, hdferr)
            if (hdferr < 0) exit ops
            call self%open_attribute_for_write(object, name, stype, space, attr, error)
            if (allocated(error)) exit ops
            call h5awrite_f(attr, stype, buf, hdferr)
        end block ops
        call release_written(attr, hdferr)
        call release(space)
        call release(stype)
        if (.not. allocated(error) .and. hdferr < 0) call attr_error(self, 'write', object, &
                                                                     name, error)
    end subroutine write_attr_string

    !> Write a real scalar attribute.
    subroutine write_attr_real(self, object, name, value, error)
        !> A file open for writing.
        class(h5_file_t), intent(inout) :: self
        !> Path of the group or dataset carrying the attribute ('/' for the root).
        character(len=*), intent(in) :: object
        !> Attribute name.
        character(len=*), intent(in) :: name
        !> Value.
        real(wp), intent(in) :: value
        !> Set on failure.
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: space, attr
        integer(hsize_t) :: dims(1)
        integer :: hdferr
        dims = 1
        space = -1
        attr = -1
        ops: block
            call h5screate_f(h5s_scalar_f, space, hdferr)
            if (hdferr < 0) exit ops
            call self%open_attribute_for_write(object, name, h5t_ieee_f64le, space, attr, error)
            if (allocated(error)) exit ops
            call h5awrite_f(attr, h5t_native_double, value, dims, hdferr)
        end block ops
        call release_written(attr, hdferr)
        call release(space)
        if (.not. allocated(error) .and. hdferr < 0) call attr_error(self, 'write', object, &
                                                                     name, error)
    end subroutine write_attr_real

    !> Write an integer scalar attribute.
    subroutine write_attr_int(self, object, name, value, error)
        !> A file open for writing.
        class(h5_file_t), intent(inout) :: self
        !> Path of the group or dataset carrying the attribute ('/' for the root).
        character(len=*), intent(in) :: object
        !> Attribute name.
        character(len=*), intent(in) :: name
        !> Value.
        integer, intent(in) :: value
        !> Set on failure.
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: space, attr
        integer(hsize_t) :: dims(1)
        integer :: hdferr
        dims = 1
        space = -1
        attr = -1
        ops: block
            call h5screate_f(h5s_scalar_f, space, hdferr)
            if (hdferr < 0) exit ops
            call self%open_attribute_for_write(object, name, h5t_std_i32le, space, attr, error)
            if (allocated(error)) exit ops
            call h5awrite_f(attr, h5t_native_integer, value, dims, hdferr)
        end block ops
        call release_written(attr, hdferr)
        call release(space)
        if (.not. allocated(error) .and. hdferr < 0) call attr_error(self, 'write', object, &
                                                                     name, error)
    end subroutine write_attr_int

    !> Write a 1-D real array attribute.
    subroutine write_attr_real_1d(self, object, name, value, error)
        !> A file open for writing.
        class(h5_file_t), intent(inout) :: self
        !> Path of the group or dataset carrying the attribute ('/' for the root).
        character(len=*), intent(in) :: object
        !> Attribute name.
        character(len=*), intent(in) :: name
        !> Values.
        real(wp), intent(in) :: value(:)
        !> Set on failure.
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: space, attr
        integer(hsize_t) :: dims(1)
        integer :: hdferr
        dims = size(value, kind=hsize_t)
        space = -1
        attr = -1
        ops: block
            call h5screate_simple_f(1, dims, space, hdferr)
            if (hdferr < 0) exit ops
            call self%open_attribute_for_write(object, name, h5t_ieee_f64le, space, attr, error)
            if (allocated(error)) exit ops
            if (size(value) > 0) call h5awrite_f(attr, h5t_native_double, value, dims, hdferr)
        end block ops
        call release_written(attr, hdferr)
        call release(space)
        if (.not. allocated(error) .and. hdferr < 0) call attr_error(self, 'write', object, &
                                                                     name, error)
    end subroutine write_attr_real_1d

    !> Read a (variable-length) string attribute.
    subroutine read_attr_string(self, object, name, value, error)
        !> An open file.
        class(h5_file_t), intent(in) :: self
        !> Path of the group or dataset carrying the attribute ('/' for the root).
        character(len=*), intent(in) :: object
        !> Attribute name.
        character(len=*), intent(in) :: name
        !> Value read.
        character(len=:), allocatable, intent(out) :: value
        !> Set when the attribute is missing or is not a variable-length string.
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: attr, ftype, mtype, space
        integer :: hdferr, type_class
        logical :: variable
        ftype = -1
        mtype = -1
        space = -1
        call self%open_attribute_for_read(object, name, attr, error)
        if (allocated(error)) return
        ops: block
            call h5aget_type_f(attr, ftype, hdferr)
            if (hdferr < 0) exit ops
            call h5tget_class_f(ftype, type_class, hdferr)
            if (hdferr < 0) exit ops
            variable = .false.
            if (type_class == h5t_string_f) call h5tis_variable_str_f(ftype, variable, hdferr)
            if (hdferr < 0) exit ops
            if (.not. variable) then
                call make_error(error, "HDF5: attribute '"//name//"' of '"//object//"' in '" &
                                //self%path//"' is not a variable-length string")
                exit ops
            end if
            call h5aget_space_f(attr, space, hdferr)
            if (hdferr < 0) exit ops
            call vl_string_type(mtype, hdferr)
            if (hdferr < 0) exit ops
            call read_vl_string(attr, mtype, space, value, hdferr)
        end block ops
        call release(space)
        call release(mtype)
        call release(ftype)
        call release(attr)
        if (.not. allocated(error) .and. hdferr < 0) call attr_error(self, 'read', object, &
                                                                     name, error)
    end subroutine read_attr_string

    !> Read one variable-length string attribute and free HDF5's copy of it.
    subroutine read_vl_string(attr, mtype, space, value, hdferr)
        !> Attribute id.
        integer(hid_t), intent(in) :: attr
        !> Variable-length string memory type.
        integer(hid_t), intent(in) :: mtype
        !> Dataspace of the attribute (scalar).
        integer(hid_t), intent(in) :: space
        !> The string.
        character(len=:), allocatable, intent(out) :: value
        !> HDF5 status (< 0 on failure).
        integer, intent(out) :: hdferr
        type(c_ptr), target :: cstring
        type(c_ptr) :: buf
        character(kind=c_char), pointer :: chars(:)
        integer :: i, n, status
        cstring = c_null_ptr
        buf = c_loc(cstring)
        call h5aread_f(attr, mtype, buf, hdferr)
        if (hdferr < 0) return
        n = 0
        if (c_associated(cstring)) n = int(c_strlen(cstring))
        allocate (character(len=n) :: value)
        if (n > 0) then
            call c_f_pointer(cstring, chars, [n])
            do i = 1, n
                value(i:i) = chars(i)
            end do
        end if
        call h5dvlen_reclaim_f(mtype, space, h5p_default_f, buf, status)
    end subroutine read_vl_string

    !> Read a real scalar attribute.
    subroutine read_attr_real(self, object, name, value, error)
        !> An open file.
        class(h5_file_t), intent(in) :: self
        !> Path of the group or dataset carrying the attribute ('/' for the root).
        character(len=*), intent(in) :: object
        !> Attribute name.
        character(len=*), intent(in) :: name
        !> Value read.
        real(wp), intent(out) :: value
        !> Set when the attribute is missing or unreadable.
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: attr
        integer(hsize_t) :: dims(1)
        integer :: hdferr
        dims = 1
        value = 0.0_wp
        call self%open_attribute_for_read(object, name, attr, error)
        if (allocated(error)) return
        call h5aread_f(attr, h5t_native_double, value, dims, hdferr)
        call release(attr)
        if (hdferr < 0) call attr_error(self, 'read', object, name, error)
    end subroutine read_attr_real

    !> Read an integer scalar attribute.
    subroutine read_attr_int(self, object, name, value, error)
        !> An open file.
        class(h5_file_t), intent(in) :: self
        !> Path of the group or dataset carrying the attribute ('/' for the root).
        character(len=*), intent(in) :: object
        !> Attribute name.
        character(len=*), intent(in) :: name
        !> Value read.
        integer, intent(out) :: value
        !> Set when the attribute is missing or unreadable.
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: attr
        integer(hsize_t) :: dims(1)
        integer :: hdferr
        dims = 1
        value = 0
        call self%open_attribute_for_read(object, name, attr, error)
        if (allocated(error)) return
        call h5aread_f(attr, h5t_native_integer, value, dims, hdferr)
        call release(attr)
        if (hdferr < 0) call attr_error(self, 'read', object, name, error)
    end subroutine read_attr_int

    !> Read a 1-D real array attribute.
    subroutine read_attr_real_1d(self, object, name, value, error)
        !> An open file.
        class(h5_file_t), intent(in) :: self
        !> Path of the group or dataset carrying the attribute ('/' for the root).
        character(len=*), intent(in) :: object
        !> Attribute name.
        character(len=*), intent(in) :: name
        !> Values read.
        real(wp), allocatable, intent(out) :: value(:)
        !> Set when the attribute is missing, unreadable or not 1-D.
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: attr, space
        integer(hsize_t) :: dims(1), maxdims(1)
        integer :: hdferr, rank
        space = -1
        call self%open_attribute_for_read(object, name, attr, error)
        if (allocated(error)) return
        ops: block
            call h5aget_space_f(attr, space, hdferr)
            if (hdferr < 0) exit ops
            call h5sget_simple_extent_ndims_f(space, rank, hdferr)
            if (hdferr < 0) exit ops
            if (rank /= 1) then
                call make_error(error, "HDF5: attribute '"//name//"' of '"//object//"' in '" &
                                //self%path//"' is not a 1-D array")
                exit ops
            end if
            call h5sget_simple_extent_dims_f(space, dims, maxdims, hdferr)
            if (hdferr < 0) exit ops
            allocate (value(dims(1)))
            if (dims(1) > 0) call h5aread_f(attr, h5t_native_double, value, dims, hdferr)
        end block ops
        call release(space)
        call release(attr)
        if (.not. allocated(error) .and. hdferr < 0) call attr_error(self, 'read', object, &
                                                                     name, error)
    end subroutine read_attr_real_1d

    !> Create attribute `name` on `object` (replacing an existing one) and return its id.
    subroutine open_attribute_for_write(self, object, name, file_type, space, attr, error)
        !> A file open for writing.
        class(h5_file_t), intent(inout) :: self
        !> Path of the group or dataset carrying the attribute.
        character(len=*), intent(in) :: object
        !> Attribute name.
        character(len=*), intent(in) :: name
        !> Datatype in the file.
        integer(hid_t), intent(in) :: file_type
        !> Dataspace of the attribute.
        integer(hid_t), intent(in) :: space
        !> Attribute id (to be released by the caller), -1 on failure.
        integer(hid_t), intent(out) :: attr
        !> Set on failure.
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: obj
        logical :: found
        integer :: hdferr
        attr = -1
        obj = -1
        call require_writable(self, object, error)
        if (allocated(error)) return
        if (.not. self%exists(object)) then
            call make_error(error, "HDF5: cannot write attribute '"//name//"': no object '" &
                            //object//"' in '"//self%path//"'")
            return
        end if
        ops: block
            call h5oopen_f(self%id, object, obj, hdferr)
            if (hdferr < 0) exit ops
            call h5aexists_f(obj, name, found, hdferr)
            if (hdferr < 0) exit ops
            if (found) call h5adelete_f(obj, name, hdferr)
            if (hdferr < 0) exit ops
            call h5acreate_f(obj, name, file_type, space, attr, hdferr)
        end block ops
        call release(obj)
        if (hdferr < 0) then
            attr = -1
            call attr_error(self, 'create', object, name, error)
        end if
    end subroutine open_attribute_for_write

    !> Open attribute `name` of `object` for reading.
    subroutine open_attribute_for_read(self, object, name, attr, error)
        !> An open file.
        class(h5_file_t), intent(in) :: self
        !> Path of the group or dataset carrying the attribute.
        character(len=*), intent(in) :: object
        !> Attribute name.
        character(len=*), intent(in) :: name
        !> Attribute id (to be released by the caller), -1 on failure.
        integer(hid_t), intent(out) :: attr
        !> Set when the object or the attribute does not exist.
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: obj
        logical :: found
        integer :: hdferr
        attr = -1
        obj = -1
        found = .false.
        if (.not. self%exists(object)) then
            call make_error(error, "HDF5: no object '"//object//"' in '"//file_name(self)//"'")
            return
        end if
        ops: block
            call h5oopen_f(self%id, object, obj, hdferr)
            if (hdferr < 0) exit ops
            call h5aexists_f(obj, name, found, hdferr)
            if (hdferr < 0 .or. .not. found) exit ops
            call h5aopen_f(obj, name, attr, hdferr)
        end block ops
        call release(obj)
        if (hdferr < 0 .or. .not. found) then
            attr = -1
            call make_error(error, "HDF5: no attribute '"//name//"' on '"//object//"' in '" &
                            //self%path//"'")
        end if
    end subroutine open_attribute_for_read

    ! ---------------------------------------------------------------------------------------
    ! Fixed-size datasets
    ! ---------------------------------------------------------------------------------------

    !> Write a 1-D real dataset.
    subroutine write_real_1d(self, path, values, error)
        !> A file open for writing.
        class(h5_file_t), intent(inout) :: self
        !> Dataset path.
        character(len=*), intent(in) :: path
        !> Values.
        real(wp), intent(in) :: values(:)
        !> Set on failure (also when the dataset exists).
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: dset
        integer(hsize_t) :: dims(1)
        integer :: hdferr
        dims = shape(values, kind=hsize_t)
        call self%new_dataset(path, h5t_ieee_f64le, dims, dims, dset, error)
        if (allocated(error)) return
        hdferr = 0
        if (size(values) > 0) call h5dwrite_f(dset, h5t_native_double, values, dims, hdferr)
        call release_written(dset, hdferr)
        if (hdferr < 0) call dataset_error(self, 'write', path, error)
    end subroutine write_real_1d

    !> Write a 2-D real dataset (h5py shape reversed).
    subroutine write_real_2d(self, path, values, error)
        !> A file open for writing.
        class(h5_file_t), intent(inout) :: self
        !> Dataset path.
        character(len=*), intent(in) :: path
        !> Values.
        real(wp), intent(in) :: values(:, :)
        !> Set on failure (also when the dataset exists).
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: dset
        integer(hsize_t) :: dims(2)
        integer :: hdferr
        dims = shape(values, kind=hsize_t)
        call self%new_dataset(path, h5t_ieee_f64le, dims, dims, dset, error)
        if (allocated(error)) return
        hdferr = 0
        if (size(values) > 0) call h5dwrite_f(dset, h5t_native_double, values, dims, hdferr)
        call release_written(dset, hdferr)
        if (hdferr < 0) call dataset_error(self, 'write', path, error)
    end subroutine write_real_2d

    !> Write a 3-D real dataset (h5py shape reversed).
    subroutine write_real_3d(self, path, values, error)
        !> A file open for writing.
        class(h5_file_t), intent(inout) :: self
        !> Dataset path.
        character(len=*), intent(in) :: path
        !> Values.
        real(wp), intent(in) :: values(:, :, :)
        !> Set on failure (also when the dataset exists).
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: dset
        integer(hsize_t) :: dims(3)
        integer :: hdferr
        dims = shape(values, kind=hsize_t)
        call self%new_dataset(path, h5t_ieee_f64le, dims, dims, dset, error)
        if (allocated(error)) return
        hdferr = 0
        if (size(values) > 0) call h5dwrite_f(dset, h5t_native_double, values, dims, hdferr)
        call release_written(dset, hdferr)
        if (hdferr < 0) call dataset_error(self, 'write', path, error)
    end subroutine write_real_3d

    !> Write a 1-D integer dataset.
    subroutine write_int_1d(self, path, values, error)
        !> A file open for writing.
        class(h5_file_t), intent(inout) :: self
        !> Dataset path.
        character(len=*), intent(in) :: path
        !> Values.
        integer, intent(in) :: values(:)
        !> Set on failure (also when the dataset exists).
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: dset
        integer(hsize_t) :: dims(1)
        integer :: hdferr
        dims = shape(values, kind=hsize_t)
        call self%new_dataset(path, h5t_std_i32le, dims, dims, dset, error)
        if (allocated(error)) return
        hdferr = 0
        if (size(values) > 0) call h5dwrite_f(dset, h5t_native_integer, values, dims, hdferr)
        call release_written(dset, hdferr)
        if (hdferr < 0) call dataset_error(self, 'write', path, error)
    end subroutine write_int_1d

    !> Write a 2-D integer dataset (h5py shape reversed).
    subroutine write_int_2d(self, path, values, error)
        !> A file open for writing.
        class(h5_file_t), intent(inout) :: self
        !> Dataset path.
        character(len=*), intent(in) :: path
        !> Values.
        integer, intent(in) :: values(:, :)
        !> Set on failure (also when the dataset exists).
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: dset
        integer(hsize_t) :: dims(2)
        integer :: hdferr
        dims = shape(values, kind=hsize_t)
        call self%new_dataset(path, h5t_std_i32le, dims, dims, dset, error)
        if (allocated(error)) return
        hdferr = 0
        if (size(values) > 0) call h5dwrite_f(dset, h5t_native_integer, values, dims, hdferr)
        call release_written(dset, hdferr)
        if (hdferr < 0) call dataset_error(self, 'write', path, error)
    end subroutine write_int_2d

    !> Read a whole 1-D real dataset.
    subroutine read_real_1d(self, path, values, error)
        !> An open file.
        class(h5_file_t), intent(in) :: self
        !> Dataset path.
        character(len=*), intent(in) :: path
        !> Values read, allocated to the dataset's shape.
        real(wp), allocatable, intent(out) :: values(:)
        !> Set when the dataset is missing, of another rank or not real.
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: dset
        integer(hsize_t) :: dims(1)
        integer :: hdferr
        call self%open_dataset(path, h5t_float_f, dims, dset, error)
        if (allocated(error)) return
        allocate (values(dims(1)))
        hdferr = 0
        if (size(values) > 0) call h5dread_f(dset, h5t_native_double, values, dims, hdferr)
        call release(dset)
        if (hdferr < 0) call dataset_error(self, 'read', path, error)
    end subroutine read_real_1d

    !> Read a whole 2-D real dataset.
    subroutine read_real_2d(self, path, values, error)
        !> An open file.
        class(h5_file_t), intent(in) :: self
        !> Dataset path.
        character(len=*), intent(in) :: path
        !> Values read, allocated to the dataset's (Fortran-order) shape.
        real(wp), allocatable, intent(out) :: values(:, :)
        !> Set when the dataset is missing, of another rank or not real.
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: dset
        integer(hsize_t) :: dims(2)
        integer :: hdferr
        call self%open_dataset(path, h5t_float_f, dims, dset, error)
        if (allocated(error)) return
        allocate (values(dims(1), dims(2)))
        hdferr = 0
        if (size(values) > 0) call h5dread_f(dset, h5t_native_double, values, dims, hdferr)
        call release(dset)
        if (hdferr < 0) call dataset_error(self, 'read', path, error)
    end subroutine read_real_2d

    !> Read a whole 3-D real dataset.
    subroutine read_real_3d(self, path, values, error)
        !> An open file.
        class(h5_file_t), intent(in) :: self
        !> Dataset path.
        character(len=*), intent(in) :: path
        !> Values read, allocated to the dataset's (Fortran-order) shape.
        real(wp), allocatable, intent(out) :: values(:, :, :)
        !> Set when the dataset is missing, of another rank or not real.
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: dset
        integer(hsize_t) :: dims(3)
        integer :: hdferr
        call self%open_dataset(path, h5t_float_f, dims, dset, error)
        if (allocated(error)) return
        allocate (values(dims(1), dims(2), dims(3)))
        hdferr = 0
        if (size(values) > 0) call h5dread_f(dset, h5t_native_double, values, dims, hdferr)
        call release(dset)
        if (hdferr < 0) call dataset_error(self, 'read', path, error)
    end subroutine read_real_3d

    !> Read a whole 1-D integer dataset.
    subroutine read_int_1d(self, path, values, error)
        !> An open file.
        class(h5_file_t), intent(in) :: self
        !> Dataset path.
        character(len=*), intent(in) :: path
        !> Values read, allocated to the dataset's shape.
        integer, allocatable, intent(out) :: values(:)
        !> Set when the dataset is missing, of another rank or not integer.
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: dset
        integer(hsize_t) :: dims(1)
        integer :: hdferr
        call self%open_dataset(path, h5t_integer_f, dims, dset, error)
        if (allocated(error)) return
        allocate (values(dims(1)))
        hdferr = 0
        if (size(values) > 0) call h5dread_f(dset, h5t_native_integer, values, dims, hdferr)
        call release(dset)
        if (hdferr < 0) call dataset_error(self, 'read', path, error)
    end subroutine read_int_1d

    !> Read a whole 2-D integer dataset.
    subroutine read_int_2d(self, path, values, error)
        !> An open file.
        class(h5_file_t), intent(in) :: self
        !> Dataset path.
        character(len=*), intent(in) :: path
        !> Values read, allocated to the dataset's (Fortran-order) shape.
        integer, allocatable, intent(out) :: values(:, :)
        !> Set when the dataset is missing, of another rank or not integer.
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: dset
        integer(hsize_t) :: dims(2)
        integer :: hdferr
        call self%open_dataset(path, h5t_integer_f, dims, dset, error)
        if (allocated(error)) return
        allocate (values(dims(1), dims(2)))
        hdferr = 0
        if (size(values) > 0) call h5dread_f(dset, h5t_native_integer, values, dims, hdferr)
        call release(dset)
        if (hdferr < 0) call dataset_error(self, 'read', path, error)
    end subroutine read_int_2d

    !> Shape of a dataset in Fortran order (the reverse of h5py's `.shape`).
    subroutine file_dataset_shape(self, path, dims, error)
        !> An open file.
        class(h5_file_t), intent(in) :: self
        !> Dataset path.
        character(len=*), intent(in) :: path
        !> Current extent of each dimension.
        integer, allocatable, intent(out) :: dims(:)
        !> Set when the dataset is missing.
        type(error_t), allocatable, intent(out) :: error
        integer(hsize_t), allocatable :: hdims(:)
        integer(hid_t) :: dset
        call dataset_dims(self, path, dset, hdims, error)
        if (allocated(error)) return
        call release(dset)
        dims = int(hdims)
    end subroutine file_dataset_shape

    !> Paths of every dataset in the file (groups visited recursively, in HDF5's name order),
    !> with the extent of the last Fortran dimension of each (the number of records of a
    !> series; 1 for a scalar dataset).
    subroutine file_list_datasets(self, paths, last_dims, error)
        !> An open file.
        class(h5_file_t), intent(in) :: self
        !> Absolute dataset paths.
        character(len=256), allocatable, intent(out) :: paths(:)
        !> Extent of the last dimension of each dataset.
        integer, allocatable, intent(out) :: last_dims(:)
        !> Set when the file cannot be read.
        type(error_t), allocatable, intent(out) :: error
        integer :: n
        allocate (paths(16), last_dims(16))
        n = 0
        if (.not. self%is_open()) then
            call make_error(error, 'HDF5: list_datasets: no file is open')
            return
        end if
        call visit('/', error)
        if (allocated(error)) return
        paths = paths(:n)
        last_dims = last_dims(:n)
    contains
        recursive subroutine visit(group, error)
            character(len=*), intent(in) :: group
            type(error_t), allocatable, intent(out) :: error
            character(len=256) :: name
            character(len=:), allocatable :: child
            integer :: members, k, obj_type, hdferr
            integer, allocatable :: dims(:)
            call h5gn_members_f(self%id, group, members, hdferr)
            if (hdferr < 0) then
                call make_error(error, "HDF5: cannot list group '"//group//"' in '"//self%path//"'")
                return
            end if
            do k = 0, members - 1
                call h5gget_obj_info_idx_f(self%id, group, k, name, obj_type, hdferr)
                if (hdferr < 0) then
                    call make_error(error, "HDF5: cannot list group '"//group//"' in '"//self%path//"'")
                    return
                end if
                if (group == '/') then
                    child = '/'//trim(name)
                else
                    child = group//'/'//trim(name)
                end if
                if (len(child) > len(paths)) then
                    call make_error(error, "HDF5: path '"//child//"' longer than 256 characters")
                    return
                end if
                if (obj_type == h5g_group_f) then
                    call visit(child, error)
                    if (allocated(error)) return
                else if (obj_type == h5g_dataset_f) then
                    call self%dataset_shape(child, dims, error)
                    if (allocated(error)) return
                    if (n == size(paths)) then
                        paths = [paths, paths]
                        last_dims = [last_dims, last_dims]
                    end if
                    n = n + 1
                    paths(n) = child
                    last_dims(n) = 1
                    if (size(dims) > 0) last_dims(n) = dims(size(dims))
                end if
            end do
        end subroutine visit
    end subroutine file_list_datasets

    !> Remove a dataset or group from the file (its space is not reused).
    subroutine file_delete(self, path, error)
        !> A file open for writing.
        class(h5_file_t), intent(inout) :: self
        !> Object path.
        character(len=*), intent(in) :: path
        !> Set when the object is missing or cannot be removed.
        type(error_t), allocatable, intent(out) :: error
        integer :: hdferr
        call require_writable(self, path, error)
        if (allocated(error)) return
        call h5ldelete_f(self%id, path, hdferr)
        if (hdferr < 0) call make_error(error, "HDF5: cannot delete '"//path//"' in '"//self%path//"'")
    end subroutine file_delete

    !> Set the number of records of a series (fewer: the last records are dropped).
    subroutine file_resize_series(self, path, n_records, error)
        !> A file open for writing.
        class(h5_file_t), intent(inout) :: self
        !> Series path.
        character(len=*), intent(in) :: path
        !> New number of records.
        integer, intent(in) :: n_records
        !> Set when the dataset is missing or cannot be resized.
        type(error_t), allocatable, intent(out) :: error
        integer(hsize_t), allocatable :: dims(:)
        integer(hid_t) :: dset
        integer :: hdferr
        call require_writable(self, path, error)
        if (allocated(error)) return
        call dataset_dims(self, path, dset, dims, error)
        if (allocated(error)) return
        if (size(dims) == 0) then
            call release(dset)
            call make_error(error, "HDF5: '"//path//"' is not a series")
            return
        end if
        dims(size(dims)) = int(n_records, hsize_t)
        call h5dset_extent_f(dset, dims, hdferr)
        call release(dset)
        if (hdferr < 0) call dataset_error(self, 'resize', path, error)
    end subroutine file_resize_series

    !> Create a new dataset (with its parent groups) and return its id.
    subroutine new_dataset(self, path, file_type, dims, maxdims, dset, error, chunk)
        !> A file open for writing.
        class(h5_file_t), intent(inout) :: self
        !> Dataset path.
        character(len=*), intent(in) :: path
        !> Datatype in the file.
        integer(hid_t), intent(in) :: file_type
        !> Current extent (Fortran order).
        integer(hsize_t), intent(in) :: dims(:)
        !> Maximum extent (h5s_unlimited_f for an extendible dimension).
        integer(hsize_t), intent(in) :: maxdims(:)
        !> Dataset id (to be released by the caller), -1 on failure.
        integer(hid_t), intent(out) :: dset
        !> Set on failure, also when the dataset already exists.
        type(error_t), allocatable, intent(out) :: error
        !> Chunk shape (required when a dimension is extendible).
        integer(hsize_t), intent(in), optional :: chunk(:)
        integer(hid_t) :: space, lcpl, dcpl
        integer :: hdferr
        dset = -1
        call require_writable(self, path, error)
        if (allocated(error)) return
        if (self%exists(path)) then
            call make_error(error, "HDF5: dataset '"//path//"' already exists in '" &
                            //self%path//"'")
            return
        end if
        space = -1
        lcpl = -1
        dcpl = -1
        ops: block
            call h5screate_simple_f(size(dims), dims, space, hdferr, maxdims)
            if (hdferr < 0) exit ops
            call link_create_plist(lcpl, hdferr)
            if (hdferr < 0) exit ops
            call h5pcreate_f(h5p_dataset_create_f, dcpl, hdferr)
            if (hdferr < 0) exit ops
            if (present(chunk)) then
                call h5pset_chunk_f(dcpl, size(chunk), chunk, hdferr)
                if (hdferr < 0) exit ops
            end if
            call h5dcreate_f(self%id, path, file_type, space, dset, hdferr, dcpl_id=dcpl, &
                             lcpl_id=lcpl)
        end block ops
        call release(dcpl)
        call release(lcpl)
        call release(space)
        if (hdferr < 0) then
            dset = -1
            call dataset_error(self, 'create', path, error)
        end if
    end subroutine new_dataset

    !> Open a dataset for reading, checking its rank (size of dims) and type class.
    subroutine open_dataset(self, path, type_class, dims, dset, error)
        !> An open file.
        class(h5_file_t), intent(in) :: self
        !> Dataset path.
        character(len=*), intent(in) :: path
        !> Expected type class (h5t_float_f or h5t_integer_f).
        integer, intent(in) :: type_class
        !> Extent of the dataset (Fortran order); its size is the expected rank.
        integer(hsize_t), intent(out) :: dims(:)
        !> Dataset id (to be released by the caller), -1 on failure.
        integer(hid_t), intent(out) :: dset
        !> Set on failure.
        type(error_t), allocatable, intent(out) :: error
        integer(hsize_t), allocatable :: hdims(:)
        integer(hid_t) :: dtype
        integer :: hdferr, actual_class
        character(len=16) :: buf
        dims = 0
        actual_class = -1
        call dataset_dims(self, path, dset, hdims, error)
        if (allocated(error)) return
        if (size(hdims) /= size(dims)) then
            write (buf, '(i0,a,i0)') size(hdims), ' instead of ', size(dims)
            call make_error(error, "HDF5: dataset '"//path//"' in '"//self%path// &
                            "' has rank "//trim(buf))
            call release(dset)
            return
        end if
        dims = hdims
        dtype = -1
        call h5dget_type_f(dset, dtype, hdferr)
        if (hdferr >= 0) call h5tget_class_f(dtype, actual_class, hdferr)
        call release(dtype)
        if (hdferr < 0 .or. actual_class /= type_class) then
            call make_error(error, "HDF5: dataset '"//path//"' in '"//self%path// &
                            "' does not hold the expected type (real or integer)")
            call release(dset)
        end if
    end subroutine open_dataset

    ! ---------------------------------------------------------------------------------------
    ! Extendible series
    ! ---------------------------------------------------------------------------------------

    !> Create an empty real series whose records have shape `record_shape` (empty for
    !> scalars, up to 2-D); records are added with `append` along a last, unlimited dimension.
    subroutine file_create_series(self, path, record_shape, error)
        !> A file open for writing.
        class(h5_file_t), intent(inout) :: self
        !> Dataset path.
        character(len=*), intent(in) :: path
        !> Shape of one record, Fortran order (`[integer ::]` for a scalar series).
        integer, intent(in) :: record_shape(:)
        !> Set on failure.
        type(error_t), allocatable, intent(out) :: error
        integer(hsize_t) :: dims(size(record_shape) + 1), maxdims(size(record_shape) + 1)
        integer(hsize_t) :: chunk(size(record_shape) + 1)
        integer(hid_t) :: dset
        integer :: r, n_per_record, hdferr
        r = size(record_shape)
        if (r > 2 .or. any(record_shape < 1)) then
            call make_internal_error(error, 'HDF5 create_series', "series '"//path//"': records must "// &
                                     "be scalars, 1-D or 2-D with positive extents")
            return
        end if
        n_per_record = product(record_shape)
        dims(:r) = int(record_shape, hsize_t)
        dims(r + 1) = 0
        maxdims(:r) = dims(:r)
        maxdims(r + 1) = h5s_unlimited_f
        chunk(:r) = dims(:r)
        chunk(r + 1) = max(1, min(max_chunk_records, chunk_bytes/(8*n_per_record)))
        call self%new_dataset(path, h5t_ieee_f64le, dims, maxdims, dset, error, chunk)
        if (allocated(error)) return
        hdferr = 0
        call release_written(dset, hdferr)
        if (hdferr < 0) call dataset_error(self, 'create', path, error)
    end subroutine file_create_series

    !> Create an empty integer series of scalar records (a 1-D extendible dataset of 32-bit
    !> integers); values are added with `append_chunk`.
    subroutine file_create_int_series(self, path, error)
        !> A file open for writing.
        class(h5_file_t), intent(inout) :: self
        !> Dataset path.
        character(len=*), intent(in) :: path
        !> Set on failure.
        type(error_t), allocatable, intent(out) :: error
        integer(hsize_t) :: dims(1), maxdims(1), chunk(1)
        integer(hid_t) :: dset
        integer :: hdferr
        dims = 0
        maxdims = h5s_unlimited_f
        chunk = max(1, min(max_chunk_records, chunk_bytes/4))
        call self%new_dataset(path, h5t_std_i32le, dims, maxdims, dset, error, chunk)
        if (allocated(error)) return
        hdferr = 0
        call release_written(dset, hdferr)
        if (hdferr < 0) call dataset_error(self, 'create', path, error)
    end subroutine file_create_int_series

    !> Append size(values) scalar records to a real scalar series.
    subroutine append_chunk_real(self, path, values, error)
        !> A file open for writing.
        class(h5_file_t), intent(inout) :: self
        !> Series path.
        character(len=*), intent(in) :: path
        !> The records (possibly none).
        real(wp), intent(in) :: values(:)
        !> Set when the series is missing, is not a real scalar series, or on failure.
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: dset, fspace, mspace
        integer(hsize_t) :: mdims(1)
        integer :: hdferr
        call self%extend_series(path, h5t_float_f, 0, size(values), dset, fspace, mspace, &
                                error)
        if (allocated(error) .or. dset < 0) return
        mdims = size(values, kind=hsize_t)
        call h5dwrite_f(dset, h5t_native_double, values, mdims, hdferr, mem_space_id=mspace, &
                        file_space_id=fspace)
        call release(mspace)
        call release(fspace)
        call release_written(dset, hdferr)
        if (hdferr < 0) call dataset_error(self, 'append to', path, error)
    end subroutine append_chunk_real

    !> Append the size(values, 2) columns of `values` as records of a real series whose
    !> records are 1-D of size(values, 1) values.
    subroutine append_chunk_real_2d(self, path, values, error)
        !> A file open for writing.
        class(h5_file_t), intent(inout) :: self
        !> Series path.
        character(len=*), intent(in) :: path
        !> The records, one per column (possibly none).
        real(wp), intent(in) :: values(:, :)
        !> Set when the series is missing, its records are not of size(values, 1) reals, or
        !> on failure.
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: dset, fspace, mspace
        integer(hsize_t) :: mdims(1)
        integer :: hdferr
        call self%extend_series(path, h5t_float_f, size(values, 1), size(values, 2), dset, &
                                fspace, mspace, error)
        if (allocated(error) .or. dset < 0) return
        mdims = size(values, kind=hsize_t)
        call h5dwrite_f(dset, h5t_native_double, reshape(values, [size(values)]), mdims, &
                        hdferr, mem_space_id=mspace, file_space_id=fspace)
        call release(mspace)
        call release(fspace)
        call release_written(dset, hdferr)
        if (hdferr < 0) call dataset_error(self, 'append to', path, error)
    end subroutine append_chunk_real_2d

    !> Append size(values) records to an integer series.
    subroutine append_chunk_int(self, path, values, error)
        !> A file open for writing.
        class(h5_file_t), intent(inout) :: self
        !> Series path.
        character(len=*), intent(in) :: path
        !> The records (possibly none).
        integer, intent(in) :: values(:)
        !> Set when the series is missing, is not an integer series, or on failure.
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: dset, fspace, mspace
        integer(hsize_t) :: mdims(1)
        integer :: hdferr
        call self%extend_series(path, h5t_integer_f, 0, size(values), dset, fspace, mspace, &
                                error)
        if (allocated(error) .or. dset < 0) return
        mdims = size(values, kind=hsize_t)
        call h5dwrite_f(dset, h5t_native_integer, values, mdims, hdferr, mem_space_id=mspace, &
                        file_space_id=fspace)
        call release(mspace)
        call release(fspace)
        call release_written(dset, hdferr)
        if (hdferr < 0) call dataset_error(self, 'append to', path, error)
    end subroutine append_chunk_int

    !> Open a series, check its type class and record size, extend it by `count` records and
    !> select them: on return the caller writes `count` records through `mspace` (memory)
    !> and `fspace` (file) into `dset`, then releases the three ids. With count = 0 nothing
    !> is changed and dset = -1 (nothing to write).
    subroutine extend_series(self, path, type_class, record_size, count, dset, fspace, &
                             mspace, error)
        !> A file open for writing.
        class(h5_file_t), intent(inout) :: self
        !> Series path.
        character(len=*), intent(in) :: path
        !> Expected type class (h5t_float_f or h5t_integer_f).
        integer, intent(in) :: type_class
        !> Values per record (0 for a scalar series).
        integer, intent(in) :: record_size
        !> Number of records to add.
        integer, intent(in) :: count
        !> Dataset, file space and memory space ids (-1 when nothing is to be written).
        integer(hid_t), intent(out) :: dset, fspace, mspace
        !> Set on failure.
        type(error_t), allocatable, intent(out) :: error
        integer(hsize_t), allocatable :: dims(:), start(:), counts(:)
        integer(hsize_t) :: mdims(1)
        integer(hid_t) :: dtype
        integer :: r, hdferr, actual_class
        dset = -1
        fspace = -1
        mspace = -1
        call require_writable(self, path, error)
        if (allocated(error)) return
        call dataset_dims(self, path, dset, dims, error)
        if (allocated(error)) return
        r = merge(1, 0, record_size > 0)
        if (size(dims) /= r + 1) then
            call make_error(error, "HDF5: series '"//path//"': record rank does not match")
            call release(dset)
            return
        end if
        if (r == 1) then
            if (dims(1) /= int(record_size, hsize_t)) then
                call make_internal_error(error, 'HDF5 append', "series '"//path//"': record shape does not match")
                call release(dset)
                return
            end if
        end if
        dtype = -1
        actual_class = -1
        call h5dget_type_f(dset, dtype, hdferr)
        if (hdferr >= 0) call h5tget_class_f(dtype, actual_class, hdferr)
        call release(dtype)
        if (hdferr < 0 .or. actual_class /= type_class) then
            call make_error(error, "HDF5: series '"//path//"' in '"//self%path// &
                            "' does not hold the type of the records appended (real or integer)")
            call release(dset)
            return
        end if
        if (count == 0) then
            call release(dset)
            return
        end if
        allocate (start(r + 1), counts(r + 1))
        start = 0
        start(r + 1) = dims(r + 1)
        counts(:r) = dims(:r)
        counts(r + 1) = int(count, hsize_t)
        dims(r + 1) = dims(r + 1) + int(count, hsize_t)
        mdims = product(counts)
        ops: block
            call h5dset_extent_f(dset, dims, hdferr)
            if (hdferr < 0) exit ops
            call h5dget_space_f(dset, fspace, hdferr)
            if (hdferr < 0) exit ops
            call h5sselect_hyperslab_f(fspace, h5s_select_set_f, start, counts, hdferr)
            if (hdferr < 0) exit ops
            call h5screate_simple_f(1, mdims, mspace, hdferr)
        end block ops
        if (hdferr < 0) then
            call release(mspace)
            call release(fspace)
            call release(dset)
            dset = -1
            call dataset_error(self, 'extend', path, error)
        end if
    end subroutine extend_series

    !> Append a scalar record to a scalar series.
    subroutine append_0d(self, path, record, error)
        !> A file open for writing.
        class(h5_file_t), intent(inout) :: self
        !> Series path.
        character(len=*), intent(in) :: path
        !> The record.
        real(wp), intent(in) :: record
        !> Set when the series is missing or the record shape does not match.
        type(error_t), allocatable, intent(out) :: error
        call self%append_record(path, [record], [integer ::], error)
    end subroutine append_0d

    !> Append a 1-D record to a series created with a 1-D record shape.
    subroutine append_1d(self, path, record, error)
        !> A file open for writing.
        class(h5_file_t), intent(inout) :: self
        !> Series path.
        character(len=*), intent(in) :: path
        !> The record.
        real(wp), intent(in) :: record(:)
        !> Set when the series is missing or the record shape does not match.
        type(error_t), allocatable, intent(out) :: error
        call self%append_record(path, record, shape(record), error)
    end subroutine append_1d

    !> Append a 2-D record to a series created with a 2-D record shape.
    subroutine append_2d(self, path, record, error)
        !> A file open for writing.
        class(h5_file_t), intent(inout) :: self
        !> Series path.
        character(len=*), intent(in) :: path
        !> The record.
        real(wp), intent(in) :: record(:, :)
        !> Set when the series is missing or the record shape does not match.
        type(error_t), allocatable, intent(out) :: error
        call self%append_record(path, reshape(record, [size(record)]), shape(record), error)
    end subroutine append_2d

    !> Extend a series by one record and write it (values in Fortran order).
    subroutine append_record(self, path, values, record_shape, error)
        !> A file open for writing.
        class(h5_file_t), intent(inout) :: self
        !> Series path.
        character(len=*), intent(in) :: path
        !> The record, flattened in Fortran order.
        real(wp), intent(in) :: values(:)
        !> Shape of the record.
        integer, intent(in) :: record_shape(:)
        !> Set on failure.
        type(error_t), allocatable, intent(out) :: error
        integer(hsize_t), allocatable :: dims(:), start(:), count(:)
        integer(hsize_t) :: mdims(1)
        integer(hid_t) :: dset, fspace, mspace
        integer :: r, hdferr
        call require_writable(self, path, error)
        if (allocated(error)) return
        call dataset_dims(self, path, dset, dims, error)
        if (allocated(error)) return
        r = size(record_shape)
        if (size(dims) /= r + 1) then
            call make_error(error, "HDF5: series '"//path//"': record rank does not match")
            call release(dset)
            return
        end if
        if (any(dims(:r) /= int(record_shape, hsize_t))) then
            call make_internal_error(error, 'HDF5 append', "series '"//path//"': record shape does not match")
            call release(dset)
            return
        end if
        fspace = -1
        mspace = -1
        allocate (start(r + 1), count(r + 1))
        start = 0
        start(r + 1) = dims(r + 1)
        count(:r) = dims(:r)
        count(r + 1) = 1
        dims(r + 1) = dims(r + 1) + 1
        mdims = size(values, kind=hsize_t)
        ops: block
            call h5dset_extent_f(dset, dims, hdferr)
            if (hdferr < 0) exit ops
            call h5dget_space_f(dset, fspace, hdferr)
            if (hdferr < 0) exit ops
            call h5sselect_hyperslab_f(fspace, h5s_select_set_f, start, count, hdferr)
            if (hdferr < 0) exit ops
            call h5screate_simple_f(1, mdims, mspace, hdferr)
            if (hdferr < 0) exit ops
            call h5dwrite_f(dset, h5t_native_double, values, mdims, hdferr, mem_space_id=mspace, &
                            file_space_id=fspace)
        end block ops
        call release(mspace)
        call release(fspace)
        call release_written(dset, hdferr)
        if (hdferr < 0) call dataset_error(self, 'append to', path, error)
    end subroutine append_record

    ! ---------------------------------------------------------------------------------------
    ! Helpers
    ! ---------------------------------------------------------------------------------------

    !> Open a dataset and return its id and current extent (Fortran order).
    subroutine dataset_dims(self, path, dset, dims, error)
        !> An open file.
        class(h5_file_t), intent(in) :: self
        !> Dataset path.
        character(len=*), intent(in) :: path
        !> Dataset id (to be released by the caller), -1 on failure.
        integer(hid_t), intent(out) :: dset
        !> Current extent.
        integer(hsize_t), allocatable, intent(out) :: dims(:)
        !> Set when the dataset is missing.
        type(error_t), allocatable, intent(out) :: error
        integer(hsize_t), allocatable :: maxdims(:)
        integer(hid_t) :: space
        integer :: hdferr, rank
        dset = -1
        space = -1
        if (.not. self%exists(path)) then
            call make_error(error, "HDF5: no dataset '"//path//"' in '"//file_name(self)//"'")
            return
        end if
        ops: block
            call h5dopen_f(self%id, path, dset, hdferr)
            if (hdferr < 0) exit ops
            call h5dget_space_f(dset, space, hdferr)
            if (hdferr < 0) exit ops
            call h5sget_simple_extent_ndims_f(space, rank, hdferr)
            if (hdferr < 0) exit ops
            allocate (dims(rank), maxdims(rank))
            if (rank > 0) call h5sget_simple_extent_dims_f(space, dims, maxdims, hdferr)
        end block ops
        call release(space)
        if (hdferr < 0) then
            call release(dset)
            dset = -1
            call make_error(error, "HDF5: '"//path//"' in '"//self%path//"' is not a readable " &
                            //"dataset")
        end if
    end subroutine dataset_dims

    !> Start the HDF5 library if it is not running (idempotent, no module state).
    subroutine ensure_library(error)
        !> Set when the library cannot start.
        type(error_t), allocatable, intent(out) :: error
        logical :: valid
        integer :: hdferr
        ! Before any other HDF5 call (the first one starts the C library and registers its exit
        ! handler); it fails harmlessly when called again.
        call h5dont_atexit_f(hdferr)
        ! The predefined type ids are valid exactly while the Fortran library is open.
        call h5iis_valid_f(h5t_native_double, valid, hdferr)
        if (hdferr >= 0 .and. valid) return
        call h5open_f(hdferr)
        if (hdferr < 0) then
            call make_error(error, 'HDF5: cannot initialise the HDF5 library')
            return
        end if
        call h5eset_auto_f(0, hdferr)
    end subroutine ensure_library

    !> Error unless the file is open for writing.
    subroutine require_writable(self, path, error)
        !> The file object.
        class(h5_file_t), intent(in) :: self
        !> Object being written (for the message).
        character(len=*), intent(in) :: path
        !> Set when the file is not open for writing.
        type(error_t), allocatable, intent(out) :: error
        if (.not. self%writable .or. .not. self%is_open()) then
            call make_error(error, "HDF5: cannot write '"//path//"': file '"//file_name(self) &
                            //"' is not open for writing")
        end if
    end subroutine require_writable

    !> A link creation property list that creates missing intermediate groups.
    subroutine link_create_plist(lcpl, hdferr)
        !> Property list id (to be released by the caller).
        integer(hid_t), intent(out) :: lcpl
        !> HDF5 status (< 0 on failure).
        integer, intent(out) :: hdferr
        call h5pcreate_f(h5p_link_create_f, lcpl, hdferr)
        if (hdferr < 0) return
        call h5pset_create_inter_group_f(lcpl, 1, hdferr)
    end subroutine link_create_plist

    !> The variable-length, null-terminated UTF-8 C string datatype (what h5py writes for
    !> `str`).
    subroutine vl_string_type(stype, hdferr)
        !> Datatype id (to be released by the caller).
        integer(hid_t), intent(out) :: stype
        !> HDF5 status (< 0 on failure).
        integer, intent(out) :: hdferr
        call h5tcopy_f(h5t_c_s1, stype, hdferr)
        if (hdferr < 0) return
        call h5tset_size_f(stype, h5t_variable, hdferr)
        if (hdferr < 0) return
        call h5tset_strpad_f(stype, h5t_str_nullterm_f, hdferr)
        if (hdferr < 0) return
        call h5tset_cset_f(stype, h5t_cset_utf8_f, hdferr)
    end subroutine vl_string_type

    !> Close a dataset or an attribute just written and fold the status of the close into
    !> `hdferr`: closing a dataset writes its cached chunks, so a full disk shows up here
    !> (`release` ignores it).
    subroutine release_written(id, hdferr)
        !> Identifier; set to -1.
        integer(hid_t), intent(inout) :: id
        !> Status of the write so far; set to the failure of the close if it was fine.
        integer, intent(inout) :: hdferr
        integer :: id_type, status
        if (id <= 0) return
        call h5iget_type_f(id, id_type, status)
        if (status >= 0) then
            if (id_type == h5i_dataset_f) then
                call h5dclose_f(id, status)
                id = -1
            else if (id_type == h5i_attr_f) then
                call h5aclose_f(id, status)
                id = -1
            end if
        end if
        call release(id)
        if (hdferr >= 0 .and. status < 0) hdferr = status
    end subroutine release_written

    !> Close any HDF5 identifier we own (no-op for ids <= 0).
    subroutine release(id)
        !> Identifier; set to -1.
        integer(hid_t), intent(inout) :: id
        integer :: id_type, hdferr
        if (id <= 0) return
        call h5iget_type_f(id, id_type, hdferr)
        if (hdferr >= 0) then
            if (id_type == h5i_dataset_f) then
                call h5dclose_f(id, hdferr)
            else if (id_type == h5i_dataspace_f) then
                call h5sclose_f(id, hdferr)
            else if (id_type == h5i_datatype_f) then
                call h5tclose_f(id, hdferr)
            else if (id_type == h5i_attr_f) then
                call h5aclose_f(id, hdferr)
            else if (id_type == h5i_group_f) then
                call h5gclose_f(id, hdferr)
            else if (id_type == h5i_genprop_lst_f) then
                call h5pclose_f(id, hdferr)
            else if (id_type == h5i_file_f) then
                call h5fclose_f(id, hdferr)
            else
                call h5oclose_f(id, hdferr)
            end if
        end if
        id = -1
    end subroutine release

    !> File name for messages ('(none)' before create/open).
    pure function file_name(self) result(name)
        !> The file object.
        class(h5_file_t), intent(in) :: self
        !> The name.
        character(len=:), allocatable :: name
        if (allocated(self%path)) then
            name = self%path
        else
            name = '(none)'
        end if
    end function file_name

    !> Error for a failed attribute operation.
    subroutine attr_error(self, what, object, name, error)
        !> The file object.
        class(h5_file_t), intent(in) :: self
        !> Operation ('write', 'read', 'create').
        character(len=*), intent(in) :: what
        !> Object path.
        character(len=*), intent(in) :: object
        !> Attribute name.
        character(len=*), intent(in) :: name
        !> The error.
        type(error_t), allocatable, intent(out) :: error
        call make_error(error, "HDF5: cannot "//what//" attribute '"//name//"' of '"//object// &
                        "' in '"//file_name(self)//"'")
    end subroutine attr_error

    !> Error for a failed dataset operation.
    subroutine dataset_error(self, what, path, error)
        !> The file object.
        class(h5_file_t), intent(in) :: self
        !> Operation ('write', 'read', 'create', 'append to').
        character(len=*), intent(in) :: what
        !> Dataset path.
        character(len=*), intent(in) :: path
        !> The error.
        type(error_t), allocatable, intent(out) :: error
        call make_error(error, "HDF5: cannot "//what//" dataset '"//path//"' in '" &
                        //file_name(self)//"'")
        if (what /= 'read') error%message = error%message// &
                                            ' (disk full, quota or file size limit exceeded?)'
    end subroutine dataset_error
end module io_hdf5_file
