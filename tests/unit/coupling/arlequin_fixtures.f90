!> Set-up shared by the Arlequin suites test_arlequin.pf (Debug, run-time checks) and
!> test_arlequin_long.pf (long horizons, run on the Release build by ./test.sh): a steel beam
!> (1 cm x 1 cm) and a row of 11 steel disks (R = 5 mm, thickness 1 cm) overlapping on
!> [0.2, 0.26] m, one disk on each FE node of the overlap (7 coupled disks).
module arlequin_fixtures
    use core_kinds, only: wp
    use core_error, only: error_t
    use fem_beam_config, only: beam_config_t, beam_section_t
    use dem_particles, only: particles_add_disks
    use dem_materials, only: materials_init, materials_set_pair
    use dem_moreau_jean, only: dem_system_t
    use coupling_weights, only: weight_config_t
    use coupling_arlequin, only: coupling_config_t, coupled_system_t, multipliers_nodes, coupled_beam
    use fem_beam_model, only: beam_model_t
    implicit none
    private
    public :: young, rho, area, inertia, thick, radius, pi, s0, s1, pitch, m_disk
    public :: mesh, beam_of, disk_row, coupling_of, mediator_of, fe_momentum, beam_k_max, beam_eq

    ! Steel beam 1 cm x 1 cm; steel disks of the section's depth, as thick as the section.
    real(wp), parameter :: young = 210.0e9_wp, rho = 7800.0_wp, area = 1.0e-4_wp
    real(wp), parameter :: inertia = 1.0e-8_wp/12, thick = 0.01_wp, radius = 0.005_wp
    real(wp), parameter :: pi = 3.141592653589793238462643383279502884_wp
    ! Overlap [s0, s1]: 6 elements of 1 cm, 7 nodes, one disk on each.
    real(wp), parameter :: s0 = 0.2_wp, s1 = 0.26_wp, pitch = 0.01_wp
    ! Physical mass of a disk [kg].
    real(wp), parameter :: m_disk = rho*pi*radius**2*thick

contains

    !> Uniform mesh of n elements on [a, b].
    pure function mesh(a, b, n) result(x)
        real(wp), intent(in) :: a, b
        integer, intent(in) :: n
        real(wp) :: x(n + 1)
        integer :: i
        x = [(a + (b - a)*i/n, i=0, n)]
    end function mesh

    !> Beam along x through the abscissas x, node 1 clamped when asked, no loads.
    function beam_of(x, clamped) result(config)
        real(wp), intent(in) :: x(:)
        logical, intent(in) :: clamped
        type(beam_config_t) :: config
        integer :: i, n
        n = size(x)
        config%x = x
        config%y = 0*x
        allocate (config%conn(2, n - 1))
        do i = 1, n - 1
            config%conn(:, i) = [i, i + 1]
        end do
        config%elem_section = [(1, i=1, n - 1)]
        config%sections = [beam_section_t(young=young, density=rho, area=area, inertia=inertia)]
        allocate (config%fixed(3, n), source=.false.)
        if (clamped) config%fixed(:, 1) = .true.
        allocate (config%loads(0), config%functions(0))
    end function beam_of

    !> The 11 disks at x = s0, s0 + 1 cm, ..., on the axis, touching; one material with
    !> friction mu, no restitution, cohesion sigma; theta = 1/2, step h, NLGS tolerance tol.
    function disk_row(h, mu, sigma, tol) result(dem)
        real(wp), intent(in) :: h, mu, sigma, tol
        type(dem_system_t) :: dem
        type(error_t), allocatable :: error
        real(wp) :: x(11)
        integer :: j
        x = [(s0 + pitch*j, j=0, 10)]
        call materials_init(dem%materials, 1, error)
        call materials_set_pair(dem%materials, 1, 1, mu, 0.0_wp, sigma, error)
        call particles_add_disks(dem%particles, x, 0*x, 0*x + radius, [rho], error)
        if (allocated(error)) error stop 'disk_row: '//error%message
        dem%scheme%h = h
        dem%scheme%theta = 0.5_wp
        dem%scheme%alert = 0.1_wp*radius
        dem%solver%tol = tol
        dem%solver%max_sweeps = 100000
    end function disk_row

    !> Coupling on [s0, s1] with the given weight shape.
    function coupling_of(shape, rotation_row) result(config)
        character(len=*), intent(in) :: shape
        logical, intent(in) :: rotation_row
        type(coupling_config_t) :: config
        config%weight = weight_config_t(shape=shape, s_fe=s0, s_particle=s1)
        config%thickness = thick
        config%rotation_row = rotation_row
    end function coupling_of

    !> Same with the multipliers on the FE nodes (mediator space).
    function mediator_of(shape, rotation_row) result(config)
        character(len=*), intent(in) :: shape
        logical, intent(in) :: rotation_row
        type(coupling_config_t) :: config
        config = coupling_of(shape, rotation_row)
        config%multipliers = multipliers_nodes
    end function mediator_of

    !> Linear momentum (x, y) of the FE model [kg m/s]: sums of M v over the translations.
    function fe_momentum(sys) result(p)
        type(coupled_system_t), intent(in) :: sys
        real(wp) :: p(2)
        real(wp) :: mv(sys%model%n_free)
        type(beam_model_t) :: model
        integer :: i, d
        call weighted_beam(sys, model)
        call sys%model%mass_times(sys%fe%v, mv)
        p = 0.0_wp
        do i = 1, model%n_nodes
            do d = 1, 2
                if (model%eq(d, i) > 0) p(d) = p(d) + mv(model%eq(d, i))
            end do
        end do
    end function fe_momentum

    !> Largest stiffness entry of the coupled system's weighted beam [N/m].
    function beam_k_max(sys) result(k_max)
        type(coupled_system_t), intent(in) :: sys
        real(wp) :: k_max
        type(beam_model_t) :: model
        call weighted_beam(sys, model)
        k_max = maxval(abs(model%k%ab))
    end function beam_k_max

    !> Equation number of DOF d of beam node i in the coupled system.
    integer function beam_eq(sys, d, i)
        type(coupled_system_t), intent(in) :: sys
        integer, intent(in) :: d, i
        type(beam_model_t) :: model
        call weighted_beam(sys, model)
        beam_eq = model%eq(d, i)
    end function beam_eq

    ! The weighted beam of a coupled system built by build_coupled_system (stops the test
    ! program on the internal error of another system: a fixture's bug).
    subroutine weighted_beam(sys, model)
        type(coupled_system_t), intent(in) :: sys
        type(beam_model_t), intent(out) :: model
        type(error_t), allocatable :: error
        call coupled_beam(sys, model, error)
        if (allocated(error)) error stop error%message
    end subroutine weighted_beam
end module arlequin_fixtures
