!> Point location in a 2D mesh (doc/continuum.md, "Arlequin coupling in 2D"): the element
!> holding a point and the point's natural coordinates, through a cell grid, never a loop over
!> all elements.
!>
!> The grid covers the bounding box of the mesh with about one cell per element (square-ish
!> cells of the mean element bounding-box size). Every element is registered in each cell
!> its bounding box touches (compressed rows, elements in increasing order). A query tests
!> only the elements of the point's cell: bounding box first, then the element's inverse
!> isoparametric map (`element2d_t%inverse_map`: barycentric, exact, for T3; Newton from the
!> centre for Q4, converged when the step is below 1e-14, at most 30 iterations). The point is
!> in the element when the map converged and its natural coordinates lie in the reference
!> element up to 1e-10 (`element2d_t%inside`). The first such element in element
!> order is returned, so that a point on a shared edge gets the same element as a brute-force
!> search in element order (`locate_brute`, kept for the tests).
module coupling_locate2d
    use core_kinds, only: wp
    use core_constants, only: relative_roundoff
    use fem_mesh2d, only: mesh2d_t
    use fem_element_registry, only: element_slot_t, new_element
    implicit none
    private
    public :: element_grid_t, build_element_grid, locate_brute, inverse_map

    !> Tolerance on the natural coordinates for a point to belong to an element.
    real(wp), parameter :: inside_tol = 1.0e-10_wp

    !> The cell grid of a mesh.
    type :: element_grid_t
        !> Cells along x and y.
        integer :: nx = 0, ny = 0
        !> Lower-left corner of the grid and cell sizes [m].
        real(wp) :: x0 = 0.0_wp, y0 = 0.0_wp, dx = 1.0_wp, dy = 1.0_wp
        !> First entry of each cell in `items` (nx ny + 1).
        integer, allocatable :: start(:)
        !> Elements of the cells, cell by cell, increasing within a cell.
        integer, allocatable :: items(:)
        !> Bounding box of each element (4, n_elements): xmin, xmax, ymin, ymax [m].
        real(wp), allocatable :: bbox(:, :)
    contains
        !> Element holding a point and its natural coordinates.
        procedure :: locate => grid_locate
        !> Number of candidate elements tested for a point (the cell's population).
        procedure :: candidates => grid_candidates
    end type element_grid_t

contains

    !> Build the grid of a mesh.
    pure subroutine build_element_grid(mesh, grid)
        !> The mesh.
        type(mesh2d_t), intent(in) :: mesh
        !> The grid.
        type(element_grid_t), intent(out) :: grid
        integer :: e, ne, i, j, i0, i1, j0, j1, c
        integer, allocatable :: fill(:)
        real(wp) :: h, lx, ly
        real(wp), allocatable :: xe(:, :)
        ne = mesh%element_count()
        allocate (grid%bbox(4, ne))
        do e = 1, ne
            xe = mesh%element_coordinates(e)
            grid%bbox(:, e) = [minval(xe(1, :)), maxval(xe(1, :)), minval(xe(2, :)), maxval(xe(2, :))]
        end do
        grid%x0 = minval(grid%bbox(1, :))
        grid%y0 = minval(grid%bbox(3, :))
        lx = maxval(grid%bbox(2, :)) - grid%x0
        ly = maxval(grid%bbox(4, :)) - grid%y0
        ! Mean element size; at least a tiny positive cell for degenerate extents.
        h = sum(max(grid%bbox(2, :) - grid%bbox(1, :), grid%bbox(4, :) - grid%bbox(3, :)))/ne
        h = max(h, relative_roundoff*max(lx, ly, 1.0e-300_wp))
        grid%nx = max(1, min(ceiling(lx/h), 4*ne))
        grid%ny = max(1, min(ceiling(ly/h), 4*ne))
        grid%dx = max(lx, h)/grid%nx
        grid%dy = max(ly, h)/grid%ny
        allocate (grid%start(grid%nx*grid%ny + 1), source=0)
        ! Two passes: count, then fill in element order.
        do e = 1, ne
            call cell_range(grid, grid%bbox(:, e), i0, i1, j0, j1)
            do j = j0, j1
                do i = i0, i1
                    c = (j - 1)*grid%nx + i
                    grid%start(c + 1) = grid%start(c + 1) + 1
                end do
            end do
        end do
        grid%start(1) = 1
        do c = 1, grid%nx*grid%ny
            grid%start(c + 1) = grid%start(c + 1) + grid%start(c)
        end do
        allocate (grid%items(grid%start(grid%nx*grid%ny + 1) - 1))
        fill = grid%start(1:grid%nx*grid%ny)
        do e = 1, ne
            call cell_range(grid, grid%bbox(:, e), i0, i1, j0, j1)
            do j = j0, j1
                do i = i0, i1
                    c = (j - 1)*grid%nx + i
                    grid%items(fill(c)) = e
                    fill(c) = fill(c) + 1
                end do
            end do
        end do
    end subroutine build_element_grid

    !> Cells touched by a box (clamped to the grid).
    pure subroutine cell_range(grid, box, i0, i1, j0, j1)
        type(element_grid_t), intent(in) :: grid
        real(wp), intent(in) :: box(4)
        integer, intent(out) :: i0, i1, j0, j1
        i0 = cell_index(box(1), grid%x0, grid%dx, grid%nx)
        i1 = cell_index(box(2), grid%x0, grid%dx, grid%nx)
        j0 = cell_index(box(3), grid%y0, grid%dy, grid%ny)
        j1 = cell_index(box(4), grid%y0, grid%dy, grid%ny)
    end subroutine cell_range

    !> Cell index of a coordinate, clamped to 1..n.
    pure integer function cell_index(x, x0, d, n) result(i)
        real(wp), intent(in) :: x, x0, d
        integer, intent(in) :: n
        i = min(max(int((x - x0)/d) + 1, 1), n)
    end function cell_index

    !> Element e holding (x, y) (0 when none) and natural coordinates xi.
    pure subroutine grid_locate(self, mesh, x, y, e, xi)
        !> The grid of the mesh.
        class(element_grid_t), intent(in) :: self
        !> The mesh.
        type(mesh2d_t), intent(in) :: mesh
        !> The point [m].
        real(wp), intent(in) :: x, y
        !> Element (0 when the point is in no element).
        integer, intent(out) :: e
        !> Natural coordinates in that element.
        real(wp), intent(out) :: xi(2)
        integer :: c, k, cand
        logical :: inside
        real(wp) :: slack
        e = 0
        xi = 0.0_wp
        if (size(self%bbox, 2) == 0) return
        ! Points just outside the grid (rounding) still get their border cell.
        slack = 1.0e-9_wp*max(self%dx, self%dy)
        if (x < self%x0 - slack .or. x > self%x0 + self%nx*self%dx + slack .or. &
            y < self%y0 - slack .or. y > self%y0 + self%ny*self%dy + slack) return
        c = (cell_index(y, self%y0, self%dy, self%ny) - 1)*self%nx + cell_index(x, self%x0, self%dx, self%nx)
        do k = self%start(c), self%start(c + 1) - 1
            cand = self%items(k)
            associate (b => self%bbox(:, cand))
                if (x < b(1) - slack .or. x > b(2) + slack .or. y < b(3) - slack .or. y > b(4) + slack) cycle
            end associate
            call inverse_map(mesh, cand, x, y, xi, inside)
            if (inside) then
                e = cand
                return
            end if
        end do
        xi = 0.0_wp
    end subroutine grid_locate

    !> Number of elements registered in the cell of (x, y) (0 outside the grid).
    pure integer function grid_candidates(self, x, y) result(n)
        !> The grid.
        class(element_grid_t), intent(in) :: self
        !> The point [m].
        real(wp), intent(in) :: x, y
        integer :: c
        n = 0
        if (size(self%bbox, 2) == 0) return
        c = (cell_index(y, self%y0, self%dy, self%ny) - 1)*self%nx + cell_index(x, self%x0, self%dx, self%nx)
        n = self%start(c + 1) - self%start(c)
    end function grid_candidates

    !> Reference search over all elements in order (tests only).
    pure subroutine locate_brute(mesh, x, y, e, xi)
        !> The mesh.
        type(mesh2d_t), intent(in) :: mesh
        !> The point [m].
        real(wp), intent(in) :: x, y
        !> First element holding the point (0 when none).
        integer, intent(out) :: e
        !> Natural coordinates in that element.
        real(wp), intent(out) :: xi(2)
        integer :: k
        logical :: inside
        e = 0
        do k = 1, mesh%element_count()
            call inverse_map(mesh, k, x, y, xi, inside)
            if (inside) then
                e = k
                return
            end if
        end do
        xi = 0.0_wp
    end subroutine locate_brute

    !> Natural coordinates of (x, y) in element e by its kind's inverse map (barycentric for T3,
    !> xi, eta with N = (1 - xi - eta, xi, eta); Newton for Q4, xi, eta in [-1, 1]); inside is
    !> true when the map converged and they lie in the reference element up to 1e-10.
    pure subroutine inverse_map(mesh, e, x, y, xi, inside)
        !> The mesh.
        type(mesh2d_t), intent(in) :: mesh
        !> Element.
        integer, intent(in) :: e
        !> The point [m].
        real(wp), intent(in) :: x, y
        !> Natural coordinates.
        real(wp), intent(out) :: xi(2)
        !> The point lies in the element.
        logical, intent(out) :: inside
        type(element_slot_t) :: slot
        logical :: converged
        call new_element(mesh%kind(e), slot)
        call slot%element%inverse_map(mesh%element_coordinates(e), [x, y], xi, converged)
        inside = converged
        if (inside) inside = slot%element%inside(xi, inside_tol)
    end subroutine inverse_map
end module coupling_locate2d
