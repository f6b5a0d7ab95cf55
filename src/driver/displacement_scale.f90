!> The size of a linear run's displacements against the size of its model: a warning when the
!> largest displacement exceeds `max_displacement_ratio` (10 %) of the model's extent (the
!> diagonal of the bounding box of its nodes), where linear small-strain theory no longer
!> holds. Such a displacement is nearly always a unit mistake (E in MPa read as Pa, a load in
!> N for kN, lengths in mm): the run is accepted, its results written, and the warning says
!> what to check.
module driver_displacement_scale
    use core_kinds, only: wp
    use core_strings, only: sci_text
    implicit none
    private
    public :: max_displacement_ratio, largest_displacement, model_extent, large_displacement_warning

    !> Largest displacement, as a fraction of the model's extent, that linear theory stands.
    !> The small-strain, small-rotation kinematics drop terms of order the rotation squared.
    !> A cantilever whose end deflects by w = 10 % of its length L turns there by theta =
    !> 3 w / (2 L) = 0.15 rad; the shortening it neglects, of order theta^2 L / 2 (1 % of L), is
    !> then some 10 % of w itself, and the Green-Lagrange strain term theta^2 / 2 (1.1e-2) is
    !> no longer small beside the strains the theory keeps. The error grows in proportion to
    !> w / L: beyond 10 % the results are not the model's answer any more, and at 1e5 times
    !> the extent (a modulus in MPa read as Pa) they are meaningless.
    real(wp), parameter :: max_displacement_ratio = 0.1_wp

contains

    !> Largest nodal displacement |u| = sqrt(ux^2 + uy^2) [m].
    pure real(wp) function largest_displacement(u) result(u_max)
        !> Displacements (2, n_nodes) [m].
        real(wp), intent(in) :: u(:, :)
        u_max = 0.0_wp
        if (size(u, 2) > 0) u_max = maxval(norm2(u(1:2, :), dim=1))
    end function largest_displacement

    !> Diagonal of the bounding box of the nodes [m].
    pure real(wp) function model_extent(x, y) result(extent)
        !> Coordinates of the nodes (n_nodes each) [m].
        real(wp), intent(in) :: x(:), y(:)
        extent = 0.0_wp
        if (size(x) > 0) extent = hypot(maxval(x) - minval(x), maxval(y) - minval(y))
    end function model_extent

    !> The warning when u_max exceeds max_displacement_ratio times the extent; '' otherwise.
    function large_displacement_warning(u_max, extent, inputs) result(message)
        !> Largest displacement [m].
        real(wp), intent(in) :: u_max
        !> The model's extent (`model_extent`) [m].
        real(wp), intent(in) :: extent
        !> Deck keywords of the moduli, loads and lengths, e.g. '[beam] section, load, line'.
        character(len=*), intent(in) :: inputs
        !> The warning, or ''.
        character(len=:), allocatable :: message
        message = ''
        if (.not. (u_max > max_displacement_ratio*extent)) return
        message = 'warning: the largest displacement, '//sci_text(u_max)//' m, exceeds 10 % of the '// &
                  'model''s extent ('//sci_text(extent)//' m, the diagonal of the bounding box of its '// &
                  'nodes): linear small-strain theory does not hold at this displacement; check the units of '// &
                  'E, the loads and the lengths ('//inputs//')'
    end function large_displacement_warning
end module driver_displacement_scale
