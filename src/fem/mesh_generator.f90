!> Structured meshes of a rectangle [x0, x1] x [y0, y1] with nx x ny cells, each a Q4 or two
!> T3 (split along the diagonal from the lower-left to the upper-right corner).
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
    use fem_mesh2d, only: mesh2d_t, element_t3, element_q4
    implicit none
    private
    public :: rectangle_mesh, rectangle_size, check_rectangle_size

contains

    !> Numbers of nodes, (nx + 1)(ny + 1), and of elements, nx ny Q4 or 2 nx ny T3, of a
    !> rectangle mesh, in 64-bit integers: with nx, ny <= huge(0) = 2^31 - 1 both stay below
    !> 2^63 (2 nx ny < 2^63 - 2^33), so they cannot overflow.
    pure subroutine rectangle_size(nx, ny, triangles, n_nodes, n_elements)
        !> Number of cells along x and y (>= 1).
        integer, intent(in) :: nx, ny
        !> True: two T3 per cell; false: one Q4 per cell.
        logical, intent(in) :: triangles
        !> Number of nodes.
        integer(i8), intent(out) :: n_nodes
        !> Number of elements.
        integer(i8), intent(out) :: n_elements
        n_nodes = (int(nx, i8) + 1)*(int(ny, i8) + 1)
        n_elements = int(nx, i8)*int(ny, i8)*merge(2_i8, 1_i8, triangles)
    end subroutine rectangle_size

    !> Error when a rectangle mesh has more nodes or elements than a default integer can
    !> number (huge(0) = 2147483647: node and element indices, connectivity and sets are default
    !> integers).
    subroutine check_rectangle_size(nx, ny, triangles, error)
        !> Number of cells along x and y (>= 1).
        integer, intent(in) :: nx, ny
        !> True: two T3 per cell; false: one Q4 per cell.
        logical, intent(in) :: triangles
        !> Set when a count exceeds huge(0); the message gives both counts.
        type(error_t), allocatable, intent(out) :: error
        integer(i8) :: n_nodes, n_elements
        call rectangle_size(nx, ny, triangles, n_nodes, n_elements)
        if (max(n_nodes, n_elements) <= huge(0)) return
        call make_error(error, 'rectangle mesh: '//to_str(nx)//' x '//to_str(ny)//' cells make '// &
                        to_str(n_nodes)//' nodes and '//to_str(n_elements)//' '// &
                        merge('T3', 'Q4', triangles)//' elements, more than a mesh can number ('// &
                        to_str(huge(0))//'): use fewer cells')
    end subroutine check_rectangle_size

    !> Mesh the rectangle [x0, x1] x [y0, y1] with nx x ny quadrilaterals, or 2 nx ny triangles.
    subroutine rectangle_mesh(x0, x1, y0, y1, nx, ny, triangles, mesh, error)
        !> Left and right abscissae (x0 < x1).
        real(wp), intent(in) :: x0, x1
        !> Bottom and top ordinates (y0 < y1).
        real(wp), intent(in) :: y0, y1
        !> Number of cells along x and y (>= 1).
        integer, intent(in) :: nx, ny
        !> True: two T3 per cell; false: one Q4 per cell.
        logical, intent(in) :: triangles
        !> The mesh.
        type(mesh2d_t), intent(out) :: mesh
        !> Set when the rectangle is empty, a count is < 1, the mesh has more nodes or elements
        !> than huge(0), or its arrays cannot be allocated.
        type(error_t), allocatable, intent(out) :: error
        integer :: i, j, e, n00, n10, n11, n01, k, stat
        integer(i8) :: n_nodes, n_elements
        integer, allocatable :: edges(:, :)
        if (.not. (x1 > x0 .and. y1 > y0)) then
            call make_error(error, 'rectangle mesh: need x0 < x1 and y0 < y1')
            return
        end if
        if (nx < 1 .or. ny < 1) then
            call make_error(error, 'rectangle mesh: need at least one cell in each direction')
            return
        end if
        call check_rectangle_size(nx, ny, triangles, error)
        if (allocated(error)) return
        call rectangle_size(nx, ny, triangles, n_nodes, n_elements)
        ! The largest arrays (2 coordinates, 1 kind and 4 node indices per element): a clean error
        ! when they do not fit (the model-size check of the driver refuses most such meshes before).
        allocate (mesh%x(2, n_nodes), mesh%kind(n_elements), mesh%connectivity(4, n_elements), stat=stat)
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
        mesh%kind = merge(element_t3, element_q4, triangles)
        mesh%connectivity = 0
        e = 0
        do j = 0, ny - 1
            do i = 0, nx - 1
                n00 = node(i, j)
                n10 = node(i + 1, j)
                n11 = node(i + 1, j + 1)
                n01 = node(i, j + 1)
                if (triangles) then
                    mesh%connectivity(1:3, e + 1) = [n00, n10, n11]
                    mesh%connectivity(1:3, e + 2) = [n00, n11, n01]
                    e = e + 2
                else
                    mesh%connectivity(:, e + 1) = [n00, n10, n11, n01]
                    e = e + 1
                end if
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
end module fem_mesh_generator
