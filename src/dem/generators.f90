!> Generators of disk arrangements: a row (chain), square and hexagonal lattices, and a random
!> polydisperse loose deposit in a box. They return centres and radii (to pass to
!> `particles_add_disks`), ordered row by row so that neighbours in space are close in memory.
module dem_generators
    use core_kinds, only: wp
    use core_error, only: error_t, make_error
    use dem_random, only: rng_t, rng_seed, rng_uniform_in
    implicit none
    private
    public :: generate_row, generate_square_lattice, generate_hex_lattice, generate_random_deposit

contains

    !> n disks of radius r in a straight chain from (x0, y0) along angle `angle` [rad]; centres
    !> 2r + gap apart (gap = 0: touching).
    subroutine generate_row(n, x0, y0, r, gap, angle, x, y, radius, error)
        !> Number of disks (>= 1).
        integer, intent(in) :: n
        !> Centre of the first disk [m].
        real(wp), intent(in) :: x0, y0
        !> Radius [m] (> 0).
        real(wp), intent(in) :: r
        !> Gap between neighbours [m] (>= 0).
        real(wp), intent(in) :: gap
        !> Direction of the chain from the x axis [rad].
        real(wp), intent(in) :: angle
        !> Centres and radii.
        real(wp), allocatable, intent(out) :: x(:), y(:), radius(:)
        !> Error on invalid input.
        type(error_t), allocatable, intent(out) :: error
        integer :: i
        call check_lattice(n, 1, r, gap, error)
        if (allocated(error)) return
        allocate (x(n), y(n), radius(n))
        do i = 1, n
            x(i) = x0 + (i - 1)*(2.0_wp*r + gap)*cos(angle)
            y(i) = y0 + (i - 1)*(2.0_wp*r + gap)*sin(angle)
        end do
        radius = r
    end subroutine generate_row

    !> nx * ny disks of radius r on a square lattice of pitch 2r + gap; first centre (x0, y0).
    subroutine generate_square_lattice(nx, ny, x0, y0, r, gap, x, y, radius, error)
        !> Disks per row and number of rows (>= 1).
        integer, intent(in) :: nx, ny
        !> Centre of the lower-left disk [m].
        real(wp), intent(in) :: x0, y0
        !> Radius [m] (> 0).
        real(wp), intent(in) :: r
        !> Gap between neighbours [m] (>= 0).
        real(wp), intent(in) :: gap
        !> Centres and radii, row by row.
        real(wp), allocatable, intent(out) :: x(:), y(:), radius(:)
        !> Error on invalid input.
        type(error_t), allocatable, intent(out) :: error
        call generate_lattice(nx, ny, x0, y0, r, gap, 0.0_wp, 1.0_wp, x, y, radius, error)
    end subroutine generate_square_lattice

    !> nx * ny disks of radius r on a hexagonal (triangular) lattice of pitch 2r + gap: rows
    !> sqrt(3)/2 pitch apart, every other row shifted by half a pitch; first centre (x0, y0).
    subroutine generate_hex_lattice(nx, ny, x0, y0, r, gap, x, y, radius, error)
        !> Disks per row and number of rows (>= 1).
        integer, intent(in) :: nx, ny
        !> Centre of the lower-left disk [m].
        real(wp), intent(in) :: x0, y0
        !> Radius [m] (> 0).
        real(wp), intent(in) :: r
        !> Gap between neighbours [m] (>= 0).
        real(wp), intent(in) :: gap
        !> Centres and radii, row by row.
        real(wp), allocatable, intent(out) :: x(:), y(:), radius(:)
        !> Error on invalid input.
        type(error_t), allocatable, intent(out) :: error
        call generate_lattice(nx, ny, x0, y0, r, gap, 0.5_wp, sqrt(3.0_wp)/2.0_wp, x, y, radius, &
                              error)
    end subroutine generate_hex_lattice

    !> nx * ny disks of radius r on a lattice of pitch 2r + gap along the rows, rows `rise`
    !> pitches apart, every even row shifted by `shift` pitches; first centre (x0, y0).
    subroutine generate_lattice(nx, ny, x0, y0, r, gap, shift, rise, x, y, radius, error)
        integer, intent(in) :: nx, ny
        real(wp), intent(in) :: x0, y0, r, gap
        !> Shift of the even rows and distance between rows, in pitches.
        real(wp), intent(in) :: shift, rise
        real(wp), allocatable, intent(out) :: x(:), y(:), radius(:)
        type(error_t), allocatable, intent(out) :: error
        integer :: i, j, k
        real(wp) :: pitch
        call check_lattice(nx, ny, r, gap, error)
        if (allocated(error)) return
        pitch = 2.0_wp*r + gap
        allocate (x(nx*ny), y(nx*ny), radius(nx*ny))
        k = 0
        do j = 1, ny
            do i = 1, nx
                k = k + 1
                x(k) = x0 + (i - 1)*pitch + merge(shift*pitch, 0.0_wp, mod(j, 2) == 0)
                y(k) = y0 + (j - 1)*pitch*rise
            end do
        end do
        radius = r
    end subroutine generate_lattice

    !> n disks with radii uniform in [rmin, rmax], loosely deposited in the box
    !> [xmin, xmax] x [ymin, ...): one disk per site of a square grid of pitch
    !> 2 rmax (1 + gap_ratio), filled row by row from the bottom, each disk shifted at random
    !> within its site so that no two disks overlap (they are at least 2 rmax gap_ratio apart
    !> when the shift room is used up). Deterministic for a given seed.
    subroutine generate_random_deposit(n, xmin, xmax, ymin, rmin, rmax, gap_ratio, seed, &
                                       x, y, radius, error)
        !> Number of disks (>= 1).
        integer, intent(in) :: n
        !> Box walls abscissae [m]; disks stay inside.
        real(wp), intent(in) :: xmin, xmax
        !> Box floor ordinate [m]; disks stay above it.
        real(wp), intent(in) :: ymin
        !> Radius range [m] (0 < rmin <= rmax).
        real(wp), intent(in) :: rmin, rmax
        !> Site pitch is 2 rmax (1 + gap_ratio) (>= 0).
        real(wp), intent(in) :: gap_ratio
        !> Seed of the random sequence.
        integer, intent(in) :: seed
        !> Centres and radii, row by row from the bottom.
        real(wp), allocatable, intent(out) :: x(:), y(:), radius(:)
        !> Error on invalid input (including a box narrower than one site).
        type(error_t), allocatable, intent(out) :: error
        type(rng_t) :: rng
        integer :: k, nx
        real(wp) :: pitch, room, dx, dy
        if (n < 1 .or. rmin <= 0.0_wp .or. rmax < rmin .or. gap_ratio < 0.0_wp) then
            call make_error(error, 'generate_random_deposit: need n >= 1, 0 < rmin <= rmax, gap_ratio >= 0')
            return
        end if
        pitch = 2.0_wp*rmax*(1.0_wp + gap_ratio)
        ! Never more sites per row than disks: a box wider than huge(0) sites (xmax - xmin =
        ! 1e300 m) would overflow the integer conversion.
        nx = int(min((xmax - xmin)/pitch, real(n, wp)))
        if (nx < 1) then
            call make_error(error, 'generate_random_deposit: box narrower than one disk site 2 rmax (1 + gap_ratio)')
            return
        end if
        call rng_seed(rng, seed)
        allocate (x(n), y(n), radius(n))
        do k = 1, n
            call rng_uniform_in(rng, rmin, rmax, radius(k))
            room = 0.5_wp*pitch - radius(k) - rmax*gap_ratio
            call rng_uniform_in(rng, -room, room, dx)
            call rng_uniform_in(rng, -room, room, dy)
            x(k) = xmin + (mod(k - 1, nx) + 0.5_wp)*pitch + dx
            y(k) = ymin + ((k - 1)/nx + 0.5_wp)*pitch + dy
        end do
    end subroutine generate_random_deposit

    !> Common checks of the lattice generators.
    subroutine check_lattice(nx, ny, r, gap, error)
        integer, intent(in) :: nx, ny
        real(wp), intent(in) :: r, gap
        type(error_t), allocatable, intent(out) :: error
        if (nx < 1 .or. ny < 1) then
            call make_error(error, 'disk generator: the number of disks per row and of rows must be >= 1')
        else if (r <= 0.0_wp) then
            call make_error(error, 'disk generator: the radius must be > 0')
        else if (gap < 0.0_wp) then
            call make_error(error, 'disk generator: the gap must be >= 0')
        end if
    end subroutine check_lattice
end module dem_generators
