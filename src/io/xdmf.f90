!> XDMF 2 text (the light data of ParaView's "XDMF Reader") that describes datasets of an HDF5
!> file by reference: grids, temporal and spatial collections, topology, geometry and
!> attributes whose data items are whole HDF5 datasets or hyperslabs of them (no data is
!> copied into the XML). The caller opens a file, nests collections and grids, and closes it;
!> the first write failure is kept and reported by `close` with the system's reason
!> (io_file_writer: libgfortran's units did not report a full disk or a file size limit).
!>
!> Dimensions are given in XDMF (C, h5py) order: the reverse of the Fortran shape that
!> io_hdf5_file's `dataset_shape` returns.
module io_xdmf
    use core_kinds, only: wp
    use core_error, only: error_t, make_error
    use io_file_writer, only: file_writer_t
    implicit none
    private
    public :: xdmf_file_t, xdmf_item_t, xdmf_whole, xdmf_slab

    !> A data item: a whole HDF5 dataset or a hyperslab of it.
    type :: xdmf_item_t
        !> Dataset path in the HDF5 file ('/fem/mesh/coordinates').
        character(len=:), allocatable :: dataset
        !> Shape of the dataset, XDMF (C) order.
        integer, allocatable :: dims(:)
        !> First index (0-based) and count per dimension of a hyperslab (unallocated: whole).
        integer, allocatable :: start(:), count(:)
        !> Whether the dataset holds 32-bit integers (else 64-bit reals).
        logical :: is_integer = .false.
    end type xdmf_item_t

    !> An XDMF file being written.
    type :: xdmf_file_t
        !> The open file.
        type(file_writer_t), private :: out
        !> Nesting depth (indentation).
        integer, private :: depth = 0
        !> Path of the XDMF file.
        character(len=:), allocatable, private :: path
        !> Name of the HDF5 file as seen from the XDMF file's folder.
        character(len=:), allocatable, private :: h5_name
    contains
        !> Create the file and open its Domain.
        procedure :: open => xdmf_open
        !> Close the Domain and the file; report any write failure.
        procedure :: close => xdmf_close
        !> Open a collection grid ('Temporal' or 'Spatial'), optionally at a time.
        procedure :: begin_collection => xdmf_begin_collection
        !> Open a uniform grid, optionally at a time.
        procedure :: begin_grid => xdmf_begin_grid
        !> Close the innermost grid or collection.
        procedure :: end_grid => xdmf_end_grid
        !> The topology of the current grid.
        procedure :: topology => xdmf_topology
        !> The geometry of the current grid.
        procedure :: geometry => xdmf_geometry
        !> An attribute (field) of the current grid.
        procedure :: attribute => xdmf_attribute
    end type xdmf_file_t

contains

    !> A whole dataset.
    pure function xdmf_whole(dataset, dims, is_integer) result(item)
        !> Dataset path.
        character(len=*), intent(in) :: dataset
        !> Its shape (XDMF order).
        integer, intent(in) :: dims(:)
        !> Integers (default: reals).
        logical, intent(in), optional :: is_integer
        !> The data item.
        type(xdmf_item_t) :: item
        item%dataset = dataset
        item%dims = dims
        if (present(is_integer)) item%is_integer = is_integer
    end function xdmf_whole

    !> A hyperslab (unit strides) of a real dataset.
    pure function xdmf_slab(dataset, dims, start, count) result(item)
        !> Dataset path.
        character(len=*), intent(in) :: dataset
        !> Its shape (XDMF order).
        integer, intent(in) :: dims(:)
        !> First index (0-based) and count per dimension (XDMF order).
        integer, intent(in) :: start(:), count(:)
        !> The data item.
        type(xdmf_item_t) :: item
        item%dataset = dataset
        item%dims = dims
        item%start = start
        item%count = count
    end function xdmf_slab

    !> Create `path` (replacing it) with the XML header and an open Domain.
    subroutine xdmf_open(self, path, h5_name, error)
        !> The file (closed).
        class(xdmf_file_t), intent(inout) :: self
        !> XDMF file to write.
        character(len=*), intent(in) :: path
        !> Name of the HDF5 file as seen from the XDMF file's folder.
        character(len=*), intent(in) :: h5_name
        !> Set when the file cannot be created.
        type(error_t), allocatable, intent(out) :: error
        self%path = path
        ! a file name is element text: '&' and '<' (a deck named 'a&b.dat') would end the XML.
        ! ParaView's XDMF 2 reader strips the leading bytes <= ' ' of a reference, those of a
        ! UTF-8 letter among them ('ñ.h5' becomes '.h5'): a relative name starts with './'.
        if (h5_name(1:min(1, len(h5_name))) == '/' .or. h5_name(1:min(2, len(h5_name))) == './') then
            self%h5_name = xml_text(h5_name)
        else
            self%h5_name = xml_text('./'//h5_name)
        end if
        self%depth = 0
        call self%out%create(path, 'the XDMF file', error)
        if (allocated(error)) return
        call put(self, '<?xml version="1.0" ?>')
        call put(self, '<Xdmf Version="2.0">')
        call put(self, ' <Domain>')
        self%depth = 2
    end subroutine xdmf_open

    !> Close the Domain and the file.
    subroutine xdmf_close(self, error)
        !> The file (open).
        class(xdmf_file_t), intent(inout) :: self
        !> Set when a write failed, a grid is still open, or the file cannot be closed.
        type(error_t), allocatable, intent(out) :: error
        if (.not. self%out%is_open()) return
        if (self%depth /= 2) then
            call make_error(error, "XDMF file '"//self%path//"': a grid is still open at the close")
            call self%out%discard()
            return
        end if
        self%depth = 0
        call put(self, ' </Domain>')
        call put(self, '</Xdmf>')
        call self%out%close(error)
    end subroutine xdmf_close

    !> `<Grid GridType="Collection" CollectionType="...">`, and its Time.
    subroutine xdmf_begin_collection(self, name, kind, time)
        !> The file.
        class(xdmf_file_t), intent(inout) :: self
        !> Grid name.
        character(len=*), intent(in) :: name
        !> 'Temporal' or 'Spatial'.
        character(len=*), intent(in) :: kind
        !> Time of a spatial collection inside a temporal one.
        real(wp), intent(in), optional :: time
        call put(self, '<Grid Name="'//name//'" GridType="Collection" CollectionType="'//kind//'">')
        self%depth = self%depth + 1
        if (present(time)) call put(self, '<Time Value="'//real_text(time)//'"/>')
    end subroutine xdmf_begin_collection

    !> `<Grid GridType="Uniform">`, and its Time.
    subroutine xdmf_begin_grid(self, name, time)
        !> The file.
        class(xdmf_file_t), intent(inout) :: self
        !> Grid name.
        character(len=*), intent(in) :: name
        !> Time of the grid in a temporal collection.
        real(wp), intent(in), optional :: time
        call put(self, '<Grid Name="'//name//'" GridType="Uniform">')
        self%depth = self%depth + 1
        if (present(time)) call put(self, '<Time Value="'//real_text(time)//'"/>')
    end subroutine xdmf_begin_grid

    !> `</Grid>`.
    subroutine xdmf_end_grid(self)
        !> The file.
        class(xdmf_file_t), intent(inout) :: self
        self%depth = max(2, self%depth - 1)
        call put(self, '</Grid>')
    end subroutine xdmf_end_grid

    !> `<Topology>`: 'Polyvertex' (no connectivity), 'Polyline' (2 nodes per element; without
    !> a connectivity, the segments 0-1, 2-3, ... of consecutive points),
    !> 'Triangle', 'Quadrilateral' or 'Mixed', with its connectivity.
    subroutine xdmf_topology(self, kind, n_elements, connectivity, base_offset)
        !> The file.
        class(xdmf_file_t), intent(inout) :: self
        !> XDMF topology type.
        character(len=*), intent(in) :: kind
        !> Number of elements (cells).
        integer, intent(in) :: n_elements
        !> Connectivity (none for Polyvertex).
        type(xdmf_item_t), intent(in), optional :: connectivity
        !> Number of the first node in the connectivity (1: 1-based; default 0).
        integer, intent(in), optional :: base_offset
        character(len=:), allocatable :: head
        head = '<Topology TopologyType="'//kind//'" NumberOfElements="'//int_text(n_elements)//'"'
        if (kind == 'Polyline') head = head//' NodesPerElement="2"'
        if (present(base_offset)) then
            if (base_offset /= 0) head = head//' BaseOffset="'//int_text(base_offset)//'"'
        end if
        if (.not. present(connectivity)) then
            call put(self, head//'/>')
            return
        end if
        call put(self, head//'>')
        call nested(self, connectivity)
        call put(self, '</Topology>')
    end subroutine xdmf_topology

    !> `<Geometry>` of the points: 'XY' (z = 0) or 'XYZ'.
    subroutine xdmf_geometry(self, kind, points)
        !> The file.
        class(xdmf_file_t), intent(inout) :: self
        !> XDMF geometry type.
        character(len=*), intent(in) :: kind
        !> The point coordinates.
        type(xdmf_item_t), intent(in) :: points
        call put(self, '<Geometry GeometryType="'//kind//'">')
        call nested(self, points)
        call put(self, '</Geometry>')
    end subroutine xdmf_geometry

    !> `<Attribute>`: a 'Scalar' or 'Vector' field at the 'Node's or 'Cell's (a vector of 2
    !> components is read by ParaView with z = 0, so that Warp By Vector applies).
    subroutine xdmf_attribute(self, name, kind, centre, values)
        !> The file.
        class(xdmf_file_t), intent(inout) :: self
        !> Field name.
        character(len=*), intent(in) :: name
        !> 'Scalar' or 'Vector'.
        character(len=*), intent(in) :: kind
        !> 'Node' or 'Cell'.
        character(len=*), intent(in) :: centre
        !> The values.
        type(xdmf_item_t), intent(in) :: values
        call put(self, '<Attribute Name="'//name//'" AttributeType="'//kind//'" Center="'//centre//'">')
        call nested(self, values)
        call put(self, '</Attribute>')
    end subroutine xdmf_attribute

    !> A DataItem one level deeper than its element.
    subroutine nested(self, it)
        type(xdmf_file_t), intent(inout) :: self
        type(xdmf_item_t), intent(in) :: it
        self%depth = self%depth + 1
        call item(self, it)
        self%depth = self%depth - 1
    end subroutine nested

    !> A DataItem: the HDF5 reference, inside a HyperSlab item for a slab (its Dimensions
    !> are the counts without the dimensions of count 1).
    subroutine item(self, it)
        type(xdmf_file_t), intent(inout) :: self
        type(xdmf_item_t), intent(in) :: it
        character(len=:), allocatable :: ref
        integer :: d
        if (it%is_integer) then
            ref = '<DataItem Dimensions="'//ints_text(it%dims)//'" NumberType="Int" Format="HDF">'
        else
            ref = '<DataItem Dimensions="'//ints_text(it%dims)//'" NumberType="Float" Precision="8" Format="HDF">'
        end if
        ref = ref//self%h5_name//':'//it%dataset//'</DataItem>'
        if (.not. allocated(it%start)) then
            call put(self, ref)
            return
        end if
        if (all(it%count == 1)) then
            call put(self, '<DataItem ItemType="HyperSlab" Dimensions="1" Type="HyperSlab">')
        else
            call put(self, '<DataItem ItemType="HyperSlab" Dimensions="'//ints_text(pack(it%count, it%count /= 1))// &
                     '" Type="HyperSlab">')
        end if
        self%depth = self%depth + 1
        call put(self, '<DataItem Dimensions="3 '//int_text(size(it%dims))//'" Format="XML">'// &
                 ints_text(it%start)//' '//ints_text([(1, d=1, size(it%dims))])//' '//ints_text(it%count)//'</DataItem>')
        call put(self, ref)
        self%depth = self%depth - 1
        call put(self, '</DataItem>')
    end subroutine item

    !> One line at the current depth (one space per level); the first failure is kept.
    subroutine put(self, line)
        type(xdmf_file_t), intent(inout) :: self
        character(len=*), intent(in) :: line
        call self%out%write_line(repeat(' ', self%depth)//line)
    end subroutine put

    !> A time as text, every digit of the double ('1.0000000000000000E-003').
    function real_text(x) result(text)
        real(wp), intent(in) :: x
        character(len=:), allocatable :: text
        character(len=32) :: buf
        write (buf, '(es24.16e3)') x
        text = trim(adjustl(buf))
    end function real_text

    !> An integer as text.
    pure function int_text(i) result(text)
        integer, intent(in) :: i
        character(len=:), allocatable :: text
        character(len=16) :: buf
        write (buf, '(i0)') i
        text = trim(buf)
    end function int_text

    !> Integers separated by single spaces.
    pure function ints_text(values) result(text)
        integer, intent(in) :: values(:)
        character(len=:), allocatable :: text
        integer :: k
        text = ''
        do k = 1, size(values)
            if (k > 1) text = text//' '
            text = text//int_text(values(k))
        end do
    end function ints_text

    !> Text as XML character data: `&`, `<` and `>` written as entities.
    pure function xml_text(text) result(escaped)
        !> The raw text.
        character(len=*), intent(in) :: text
        character(len=:), allocatable :: escaped
        integer :: i
        escaped = ''
        do i = 1, len(text)
            select case (text(i:i))
            case ('&')
                escaped = escaped//'&amp;'
            case ('<')
                escaped = escaped//'&lt;'
            case ('>')
                escaped = escaped//'&gt;'
            case default
                escaped = escaped//text(i:i)
            end select
        end do
    end function xml_text

end module io_xdmf
