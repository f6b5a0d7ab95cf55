!> Structured meshes of a rectangle [x0, x1] x [y0, y1] with nx x ny cells, each filled with
!> the elements of the kind asked for as that kind fills a grid cell (`element2d_t%grid_cell`:
!> a Q4, or two T3 split along the diagonal from the lower-left to the upper-right corner).
!>
!> Node (i, j), i = 0..nx, j = 0..ny, is number 1 + i + j (nx + 1). Named sets: node and edge
!> sets 'left', 'right', 'bottom', 'top' (edges counter-clockwise, outward normal to the right),
!> node set 'all' and element set 'all'.
!>
!> Nodes and elements are numbered by default integers: `rectangle_size` counts them in 64 bits
!> and `check_rectangle_size` refuses a rectangle with more than huge(0) of either, before
!> anything is allocated (the counts overflowed and the mesh was written out of bounds).
module fem_mesh_generator
    use core_kinds, only: wp, i8
    use core_error, only: error_t, make_error
    use core_strings, only: to_str
    use fem_mesh2d, only: mesh2d_t
    use fem_element2d, only: element2d_t
    use fem_element_registry, only: kind_of_name, max_node_count
    implicit none
    private
    public :: rectangle_mesh, rectangle_size, check_rectangle_size

contains

    !> Numbers of nodes, (nx + 1)(ny + 1), and of elements, nx ny times the elements per cell
    !> (1 Q4 or 2 T3), of a rectangle mesh, in 64-bit integers: with nx, ny <= huge(0) = 2^31 - 1
    !> and a few elements per cell both stay below 2^63 (2 nx ny < 2^63 - 2^33), so they cannot
    !> overflow.
    pure subroutine rectangle_size(nx, ny, element, n_nodes, n_elements)
        !> Number of cells along x and y (>= 1).
        integer, intent(in) :: nx, ny
        !> The element kind of the mesh.
        class(element2d_t), intent(in) :: element
        !> Number of nodes.
        integer(i8), intent(out) :: n_nodes
        !> Number of elements.
        integer(i8), intent(out) :: n_elements
        n_nodes = (int(nx, i8) + 1)*(int(ny, i8) + 1)
        n_elements = int(nx, i8)*int(ny, i8)*size(element%grid_cell(), 2, kind=i8)
    end subroutine rectangle_size

    !> Error when a rectangle mesh has more nodes or elements than a default integer can
    !> number (huge(0) = 2147483647: node and element indices, connectivity and sets are default
    !> integers).
    subroutine check_rectangle_size(nx, ny, element, error)
        !> Number of cells along x and y (>= 1).
        integer, intent(in) :: nx, ny
        !> The element kind of the mesh.
        class(element2d_t), intent(in) :: element
        !> Set when a count exceeds huge(0); the message gives both counts.
        type(error_t), allocatable, intent(out) :: error
        integer(i8) :: n_nodes, n_elements
        call rectangle_size(nx, ny, element, n_nodes, n_elements)
        if (max(n_nodes, n_elements) <= huge(0)) return
        call make_error(error, 'rectangle mesh: '//to_str(nx)//' x '//to_str(ny)//' cells make '// &
                        to_str(n_nodes)//' nodes and '//to_str(n_elements)//' '// &
                        upper(element%name())//' elements, more than a mesh can number ('// &
                        to_str(huge(0))//'): use fewer cells')
    end subroutine check_rectangle_size

    !> Mesh the rectangle [x0, x1] x [y0, y1] with nx x ny cells of elements of one kind.
    subroutine rectangle_mesh(x0, x1, y0, y1, nx, ny, element, mesh, error)
        !> Left and right abscissae (x0 < x1).
        real(wp), intent(in) :: x0, x1
        !> Bottom and top ordinates (y0 < y1).
        real(wp), intent(in) :: y0, y1
        !> Number of cells along x and y (>= 1).
        integer, intent(in) :: nx, ny
        !> The element kind (fem_element_registry) of the mesh.
        class(element2d_t), intent(in) :: element
        !> The mesh.
        type(mesh2d_t), intent(out) :: mesh
        !> Set when the rectangle is empty, a count is < 1, the element kind is not registered,
        !> the mesh has more nodes or elements than huge(0), or its arrays cannot be allocated.
        type(error_t), allocatable, intent(out) :: error
        integer :: i, j, e, c, k, kind, stat
        integer(i8) :: n_nodes, n_elements
        integer, allocatable :: edges(:, :), cell(:, :)
        if (.not. (x1 > x0 .and. y1 > y0)) then
            call make_error(error, 'rectangle mesh: need x0 < x1 and y0 < y1')
            return
        end if
        if (nx < 1 .or. ny < 1) then
            call make_error(error, 'rectangle mesh: need at least one cell in each direction')
            return
        end if
        kind = kind_of_name(element%name())
        if (kind == 0) then
            call make_error(error, "rectangle mesh: element kind '"//element%name()//"' is not registered")
            return
        end if
        call check_rectangle_size(nx, ny, element, error)
        if (allocated(error)) return
        call rectangle_size(nx, ny, element, n_nodes, n_elements)
        ! The largest arrays (2 coordinates, 1 kind and max_node_count() node indices per
        ! element): a clean error when they do not fit (the model-size check of the driver refuses
        ! most such meshes before).
        allocate (mesh%x(2, n_nodes), mesh%kind(n_elements), mesh%connectivity(max_node_count(), n_elements), stat=stat)
        if (stat /= 0) then
            call make_error(error, 'rectangle mesh: cannot allocate '//to_str(n_nodes)//' nodes and '// &
                            to_str(n_elements)//' elements (out of memory): use fewer cells')
            return
        end if
        do j = 0, ny
            do i = 0, nx
                mesh%x(:, node(i, j)) = [x0 + (x1 - x0)*real(i, wp)/nx, y0 + (y1 - y0)*real(j, wp)/ny]
            end do
        end do
        mesh%kind = kind
        mesh%connectivity = 0
        cell = element%grid_cell()
        e = 0
        do j = 0, ny - 1
            do i = 0, nx - 1
                associate (corners => [node(i, j), node(i + 1, j), node(i + 1, j + 1), node(i, j + 1)])
                    do c = 1, size(cell, 2)
                        e = e + 1
                        mesh%connectivity(1:size(cell, 1), e) = corners(cell(:, c))
                    end do
                end associate
            end do
        end do
        call mesh%add_node_set('left', [(node(0, j), j=0, ny)])
        call mesh%add_node_set('right', [(node(nx, j), j=0, ny)])
        call mesh%add_node_set('bottom', [(node(i, 0), i=0, nx)])
        call mesh%add_node_set('top', [(node(i, ny), i=0, nx)])
        call mesh%add_node_set('all', [(k, k=1, size(mesh%x, 2))])
        call mesh%add_element_set('all', [(k, k=1, size(mesh%kind))])
        allocate (edges(2, nx))
        edges = reshape([(node(i, 0), node(i + 1, 0), i=0, nx - 1)], [2, nx])
        call mesh%add_edge_set('bottom', edges)
        edges = reshape([(node(i + 1, ny), node(i, ny), i=nx - 1, 0, -1)], [2, nx])
        call mesh%add_edge_set('top', edges)
        deallocate (edges)
        allocate (edges(2, ny))
        edges = reshape([(node(nx, j), node(nx, j + 1), j=0, ny - 1)], [2, ny])
        call mesh%add_edge_set('right', edges)
        edges = reshape([(node(0, j + 1), node(0, j), j=ny - 1, 0, -1)], [2, ny])
        call mesh%add_edge_set('left', edges)
        ! Records the element of each edge (the orientation above is already outward).
        call mesh%orient_edges(error)

    contains

        !> Number of node (i, j).
        pure integer function node(i, j)
            integer, intent(in) :: i, j
            node = 1 + i + j*(nx + 1)
        end function node
    end subroutine rectangle_mesh

    !> Upper-case copy of an ASCII text (the element names in messages: 'T3', 'Q4').
    pure function upper(text) result(out)
        character(len=*), intent(in) :: text
        character(len=len(text)) :: out
        integer :: k
        out = text
        do k = 1, len(text)
            if (text(k:k) >= 'a' .and. text(k:k) <= 'z') out(k:k) = achar(iachar(text(k:k)) - 32)
        end do
    end function upper
end module fem_mesh_generator
