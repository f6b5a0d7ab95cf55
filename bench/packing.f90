!> Dense random packing of polydisperse disks in a box with a floor and two side walls, built
!> geometrically for the benchmark (no dynamics): sequential deposition with rolling
!> (Visscher and Bolsterli, Nature 239, 1972). Each disk is dropped at a random abscissa, falls
!> vertically until it touches a disk (or the floor), rolls down over that support until it
!> touches a second body, and stops there if it is cradled (its centre between the centres of
!> its two supports, or a support and a side wall, or on the floor); otherwise it rolls on over
!> the new support, or falls again when it rolls past the side of its support.
!>
!> Every disk rests on two bodies with zero gap: about 2 contacts per disk (coordination ~4),
!> each able to carry weight; packing fraction ~0.8 for radii in [0.8, 1.2] R. The disks are
!> numbered by rows of cells from the bottom (neighbours in space are close in memory). The
!> cost is O(N) (a cell grid of side 2 rmax; each move looks at a few cells only).
!> Deterministic for a seed.
module bench_packing
    use core_kinds, only: wp
    use core_constants, only: pi
    use dem_random, only: rng_t, rng_seed, rng_uniform_in
    implicit none
    private
    public :: deposit_disks, deposit_width, staggered_layout

    !> Expected packing fraction of the deposit (to size the box).
    real(wp), parameter :: packing_fraction = 0.82_wp
    !> Smallest rolling angle counted as progress [rad] (the start point touches its supports).
    real(wp), parameter :: angle_eps = 1.0e-9_wp
    !> Codes of the bodies met by a moving disk (disks are > 0).
    integer, parameter :: met_nothing = 0, met_floor = -1, met_left = -2, met_right = -3

    !> Cell grid of the disks already placed (cells of side 2 rmax, rows grow upwards).
    type :: grid_t
        !> Cell side [m] and box width [m].
        real(wp) :: cell = 0.0_wp, width = 0.0_wp
        !> Largest radius [m].
        real(wp) :: rmax = 0.0_wp
        !> Cells along x and rows allocated.
        integer :: ncx = 0, ncy = 0
        !> First disk of cell (cx, cy) (0-based cells; 0 = empty).
        integer, allocatable :: head(:, :)
        !> Next disk of the same cell.
        integer, allocatable :: next(:)
        !> Highest occupied row of each column (-1: none).
        integer, allocatable :: top(:)
    end type grid_t

contains

    !> Width of a box in which n disks of radii uniform in [rmin, rmax] make a deposit about
    !> `aspect` times as high as wide.
    pure real(wp) function deposit_width(n, rmin, rmax, aspect) result(width)
        !> Number of disks.
        integer, intent(in) :: n
        !> Radius range [m].
        real(wp), intent(in) :: rmin, rmax
        !> Height / width of the deposit.
        real(wp), intent(in) :: aspect
        real(wp) :: mean_r2
        if (rmax > rmin) then
            mean_r2 = (rmax**3 - rmin**3)/(3.0_wp*(rmax - rmin))
        else
            mean_r2 = rmin**2
        end if
        width = sqrt(n*pi*mean_r2/(packing_fraction*aspect))
    end function deposit_width

    !> Deposit n disks with radii uniform in [rmin, rmax] in the box x in [0, width], y >= 0.
    subroutine deposit_disks(n, width, rmin, rmax, seed, x, y, radius, stuck)
        !> Number of disks.
        integer, intent(in) :: n
        !> Box width [m] (> 2 rmax).
        real(wp), intent(in) :: width
        !> Radius range [m] (0 < rmin <= rmax).
        real(wp), intent(in) :: rmin, rmax
        !> Seed of the random sequence.
        integer, intent(in) :: seed
        !> Centres and radii, by rows of cells from the bottom.
        real(wp), allocatable, intent(out) :: x(:), y(:), radius(:)
        !> Disks left where they were after too many moves (expected 0).
        integer, intent(out) :: stuck
        type(grid_t) :: g
        type(rng_t) :: rng
        integer :: i
        logical :: ok
        call rng_seed(rng, seed)
        g%cell = 2.0_wp*rmax
        g%rmax = rmax
        g%width = width
        g%ncx = max(int(width/g%cell), 1)
        g%ncy = int(n*pi*rmax**2/(0.5_wp*width)/g%cell) + 8
        allocate (g%head(0:g%ncx - 1, 0:g%ncy - 1), source=0)
        allocate (g%next(n), source=0)
        allocate (g%top(0:g%ncx - 1), source=-1)
        allocate (x(n), y(n), radius(n))
        stuck = 0
        do i = 1, n
            call rng_uniform_in(rng, rmin, rmax, radius(i))
            call rng_uniform_in(rng, radius(i), width - radius(i), x(i))
            call place(g, i, x, y, radius, ok)
            if (.not. ok) stuck = stuck + 1
            call insert(g, i, x(i), y(i))
        end do
        call order_by_cells(g, x, y, radius)
    end subroutine deposit_disks

    !> Staggered lattice of n_row x n_rows disks with radii uniform in [0.8, 1.2] rmean, the
    !> layout of the deposit compared with Siconos (doc/performance.md): pitch p = 2.5 rmean
    !> along the rows, rows p sqrt(3)/2 apart, every odd row (the 2nd, 4th, ...) shifted by
    !> p/2 to the right; disk k = j n_row + i + 1 (row j = 0, 1, ..., column i = 0, 1, ...)
    !> at x = p (1/2 + i + mod(j, 2)/2), y = p/2 + j p sqrt(3)/2, its radius the k-th deviate
    !> of the generator of dem_random seeded with `seed` (rmean (0.8 + 0.4 u)). Box x in
    !> [0, (n_row + 1/2) p], floor y = 0. No two disks touch (centres at least p = 2.5 rmean
    !> apart, radii at most 1.2 rmean) and every disk is at least 0.05 rmean from the walls.
    pure subroutine staggered_layout(n_row, n_rows, rmean, seed, x, y, radius, width)
        !> Disks per row and number of rows.
        integer, intent(in) :: n_row, n_rows
        !> Mean radius [m].
        real(wp), intent(in) :: rmean
        !> Seed of the radii.
        integer, intent(in) :: seed
        !> Centres and radii [m], row by row from the bottom left.
        real(wp), allocatable, intent(out) :: x(:), y(:), radius(:)
        !> Box width [m].
        real(wp), intent(out) :: width
        type(rng_t) :: rng
        real(wp) :: p, rise
        integer :: i, j, k
        p = 2.5_wp*rmean
        rise = p*sqrt(3.0_wp)/2.0_wp
        width = (n_row + 0.5_wp)*p
        allocate (x(n_row*n_rows), y(n_row*n_rows), radius(n_row*n_rows))
        call rng_seed(rng, seed)
        do j = 0, n_rows - 1
            do i = 0, n_row - 1
                k = j*n_row + i + 1
                call rng_uniform_in(rng, 0.8_wp*rmean, 1.2_wp*rmean, radius(k))
                x(k) = p*(0.5_wp + i + 0.5_wp*mod(j, 2))
                y(k) = 0.5_wp*p + j*rise
            end do
        end do
    end subroutine staggered_layout

    !> Move disk i from its drop abscissa x(i) to its resting place (x(i), y(i)).
    subroutine place(g, i, x, y, radius, ok)
        type(grid_t), intent(in) :: g
        integer, intent(in) :: i
        real(wp), intent(inout) :: x(:), y(:)
        real(wp), intent(in) :: radius(:)
        logical, intent(out) :: ok
        integer, parameter :: max_moves = 10000
        real(wp) :: y0, r
        integer :: a, b, moves, left
        r = radius(i)
        y0 = huge(1.0_wp)
        left = 0
        ok = .true.
        moves = 0
        do
            call fall(g, x, y, radius, i, x(i), r, y0, left, y(i), a)
            if (a == met_floor) return
            ! roll over support a until the disk is cradled or leaves it
            do
                moves = moves + 1
                if (moves > max_moves) then
                    ok = .false.
                    return
                end if
                call roll(g, x, y, radius, i, a, x(i), y(i), b)
                if (b == met_nothing) exit
                if (b < 0) return
                if ((x(i) - x(a))*(x(i) - x(b)) < 0.0_wp) return
                a = b
            end do
            ! rolled past the side of a: fall again from there
            y0 = y(i)
            left = a
        end do
    end subroutine place

    !> Fall of disk i (abscissa xq, radius r) from height y0: first body met, `sup` (a disk or
    !> met_floor), and the height yc of the centre then. Disk `skip` (just left) is ignored.
    subroutine fall(g, x, y, radius, i, xq, r, y0, skip, yc, sup)
        type(grid_t), intent(in) :: g
        real(wp), intent(in) :: x(:), y(:), radius(:)
        integer, intent(in) :: i, skip
        real(wp), intent(in) :: xq, r, y0
        real(wp), intent(out) :: yc
        integer, intent(out) :: sup
        integer :: cx, cx0, cx1, cy, j, row0
        real(wp) :: dx, reach, h
        yc = r
        sup = met_floor
        cx0 = max(int((xq - r - g%rmax)/g%cell), 0)
        cx1 = min(int((xq + r + g%rmax)/g%cell), g%ncx - 1)
        row0 = maxval(g%top(cx0:cx1))
        if (y0 < huge(1.0_wp)) row0 = min(row0, int(y0/g%cell))
        do cy = row0, 0, -1
            ! disks of row cy and below cannot hold the disk higher than this
            if ((cy + 1)*g%cell + r + g%rmax <= yc) exit
            do cx = cx0, cx1
                j = g%head(cx, cy)
                do while (j > 0)
                    dx = xq - x(j)
                    reach = r + radius(j)
                    if (j /= skip .and. j /= i .and. abs(dx) < reach) then
                        h = y(j) + sqrt(reach*reach - dx*dx)
                        if (h > yc .and. h <= y0) then
                            yc = h
                            sup = j
                        end if
                    end if
                    j = g%next(j)
                end do
            end do
        end do
    end subroutine fall

    !> Roll disk i, at (px, py) and touching disk a, down over a (centre moving on the circle
    !> of radius r_a + r_i around a, towards the side it leans to) until it meets another body
    !> b (a disk, met_floor, met_left or met_right; the new position is returned in (px, py)),
    !> or reaches the height of a's centre without meeting anything (b = met_nothing).
    subroutine roll(g, x, y, radius, i, a, px, py, b)
        type(grid_t), intent(in) :: g
        real(wp), intent(in) :: x(:), y(:), radius(:)
        integer, intent(in) :: i, a
        real(wp), intent(inout) :: px, py
        integer, intent(out) :: b
        real(wp) :: r, d, phi0, phi_end, s, best, span, db, dist, ex, ey, along, h, qx, qy
        integer :: cx, cy, ax, ay, j, k
        r = radius(i)
        d = radius(a) + r
        phi0 = atan2(py - y(a), px - x(a))
        s = merge(1.0_wp, -1.0_wp, px >= x(a))
        phi_end = merge(0.0_wp, pi, s > 0.0_wp)
        span = s*(phi0 - phi_end)
        best = span
        b = met_nothing
        ! side walls and floor: centre on the lines x = r, x = width - r, y = r
        if (s < 0.0_wp) call try_line(acos_safe((r - x(a))/d), met_left, -angle_eps)
        if (s > 0.0_wp) call try_line(acos_safe((g%width - r - x(a))/d), met_right, -angle_eps)
        if (abs((r - y(a))/d) <= 1.0_wp) then
            call try_line(asin((r - y(a))/d), met_floor, angle_eps)
            call try_line(pi - asin((r - y(a))/d), met_floor, angle_eps)
        end if
        ! disks within r_a + 2 r + rmax of a (two cells around it)
        ax = min(int(x(a)/g%cell), g%ncx - 1)
        ay = int(y(a)/g%cell)
        do cy = max(ay - 2, 0), min(ay + 2, g%ncy - 1)
            do cx = max(ax - 2, 0), min(ax + 2, g%ncx - 1)
                j = g%head(cx, cy)
                do while (j > 0)
                    if (j /= a .and. j /= i) then
                        ! circle (a, d) meets circle (j, db) at two points
                        db = radius(j) + r
                        ex = x(j) - x(a)
                        ey = y(j) - y(a)
                        dist = sqrt(ex*ex + ey*ey)
                        if (dist < d + db .and. dist > abs(d - db)) then
                            along = (d*d - db*db + dist*dist)/(2.0_wp*dist)
                            h = sqrt(max(d*d - along*along, 0.0_wp))
                            ex = ex/dist
                            ey = ey/dist
                            do k = -1, 1, 2
                                qx = along*ex - k*h*ey
                                qy = along*ey + k*h*ex
                                call try_angle(atan2(qy, qx), j, angle_eps)
                            end do
                        end if
                    end if
                    j = g%next(j)
                end do
            end do
        end do
        px = x(a) + d*cos(phi0 - s*best)
        py = y(a) + d*sin(phi0 - s*best)
        if (b == met_left) px = r
        if (b == met_right) px = g%width - r
        if (b == met_floor) py = r
    contains
        !> Keep the body met at angle phi if it comes first along the roll (after `least`:
        !> bodies touched at the start point are ignored, except a wall the disk rolls into).
        subroutine try_angle(phi, who, least)
            real(wp), intent(in) :: phi, least
            integer, intent(in) :: who
            real(wp) :: delta
            delta = s*(phi0 - phi)
            if (delta <= -pi) delta = delta + 2.0_wp*pi
            if (delta > pi) delta = delta - 2.0_wp*pi
            if (delta > least .and. delta < best) then
                best = delta
                b = who
            end if
        end subroutine try_angle

        !> Same for a wall or the floor (phi > 2 pi: not reached).
        subroutine try_line(phi, who, least)
            real(wp), intent(in) :: phi, least
            integer, intent(in) :: who
            if (phi <= 2.0_wp*pi) call try_angle(phi, who, least)
        end subroutine try_line
    end subroutine roll

    !> acos(c) for |c| <= 1, else 4 pi (no solution).
    pure real(wp) function acos_safe(c) result(phi)
        real(wp), intent(in) :: c
        phi = 4.0_wp*pi
        if (abs(c) <= 1.0_wp) phi = acos(c)
    end function acos_safe

    !> Add disk i at (xi, yi) to its cell (rows are added as needed).
    subroutine insert(g, i, xi, yi)
        type(grid_t), intent(inout) :: g
        integer, intent(in) :: i
        real(wp), intent(in) :: xi, yi
        integer, allocatable :: tmp(:, :)
        integer :: cx, cy
        cx = min(max(int(xi/g%cell), 0), g%ncx - 1)
        cy = max(int(yi/g%cell), 0)
        if (cy >= g%ncy) then
            allocate (tmp(0:g%ncx - 1, 0:2*cy), source=0)
            tmp(:, 0:g%ncy - 1) = g%head
            call move_alloc(tmp, g%head)
            g%ncy = 2*cy + 1
        end if
        g%next(i) = g%head(cx, cy)
        g%head(cx, cy) = i
        g%top(cx) = max(g%top(cx), cy)
    end subroutine insert

    !> Renumber the disks by rows of cells from the bottom, cells from the left.
    subroutine order_by_cells(g, x, y, radius)
        type(grid_t), intent(in) :: g
        real(wp), intent(inout) :: x(:), y(:), radius(:)
        integer, allocatable :: perm(:)
        integer :: cx, cy, j, m
        allocate (perm(size(x)))
        m = 0
        do cy = 0, g%ncy - 1
            do cx = 0, g%ncx - 1
                j = g%head(cx, cy)
                do while (j > 0)
                    m = m + 1
                    perm(m) = j
                    j = g%next(j)
                end do
            end do
        end do
        x = x(perm)
        y = y(perm)
        radius = radius(perm)
    end subroutine order_by_cells
end module bench_packing
