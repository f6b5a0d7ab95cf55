!> Arlequin coupling of a 2D elastic continuum and disks (doc/continuum.md, "Coupled continuum
!> and disk runs"; doc/theory.md section 6.9): the continuum builder of the coupled system.
!> The time step, the energy audit and the generic parts of the build are those of the beam
!> (coupling_coupled_step).
!>
!> Build (`build_coupled2d`):
!> - the continuum's K_alpha and M_alpha (coupling_weighted2d, alpha = the FE weight of the
!>   overlap field, 1 outside it) and its loads: the model's own loads (nodal loads and
!>   tractions, applied in full, also inside the overlap: the disks carry no share of them)
!>   plus the weighted body force int alpha rho t N g dA = M_alpha g_nodes (the rows of
!>   M_alpha, consistent or lumped, sum to int alpha rho t N_a dA since the shape functions
!>   sum to 1), reduced to the free dofs (fem_continuum_dynamics `build_from`);
!> - every disk's weight alpha (`weight_field_t%select_disks`: 0 outside the overlap); the
!>   coupled disks are those with alpha > 0. A disk outside the overlap whose centre lies in an
!>   element is in the FE-only zone, where it would be counted twice: an error;
!> - C at the coupled centres (coupling_operator2d, elements found by the cell grid of
!>   coupling_locate2d), with the optional rotation row;
!> - the multiplier space: per coupled DOF, or the mediator space on the FE nodes whose shape
!>   functions carry coupled centres, with the L2 or H1 pairing (`build_mediator2d`).
module coupling_arlequin2d
    use core_kinds, only: wp, i8
    use core_error, only: error_t, make_error
    use fem_continuum_model, only: continuum_model_t
    use fem_continuum_dynamics, only: continuum_dynamics_t
    use fem_triplets, only: fem_triplets_t
    use fem_mass_scheme, only: mass_scheme_t, consistent_mass_t
    use dem_moreau_jean, only: dem_system_t
    use coupling_overlap2d, only: weight_field_t
    use coupling_weighted2d, only: assemble_weighted
    use coupling_locate2d, only: element_grid_t, build_element_grid
    use coupling_operator2d, only: continuum_operator_t, build_continuum_operator, build_mediator2d, &
                                   pairing_l2
    use coupling_multiplier_space, only: multiplier_space_t, mediator_space_t
    use coupling_coupled_step, only: coupled_system_t, complete_coupled_system, disk_space, notice_iface, &
                                     multipliers_particles, multipliers_nodes
    implicit none
    private
    public :: coupling2d_config_t, build_coupled2d

    !> Description of a continuum-disk coupling.
    type :: coupling2d_config_t
        !> The overlap: one region or a set of disjoint regions, with the weight's shape and floor.
        class(weight_field_t), allocatable :: region
        !> Out-of-plane thickness of the particle domain [m] (usually the continuum's), > 0.
        real(wp) :: thickness = 0.0_wp
        !> Also glue each coupled disk's rotation to the continuum's rotation 1/2 curl u.
        logical :: rotation_row = .false.
        !> Contacts on coupled disks use the condensed Delassus blocks.
        logical :: condensed_contacts = .true.
        !> Multiplier space: multipliers_particles or multipliers_nodes.
        integer :: multipliers = multipliers_particles
        !> Pairing of the mediator space: pairing_l2 or pairing_h1 (coupling_operator2d).
        integer :: pairing = pairing_l2
        !> Length l of the H1 pairing [m].
        real(wp) :: h1_length = 0.0_wp
        !> How the element masses enter M_alpha: consistent or row-sum lumped; unallocated:
        !> consistent.
        class(mass_scheme_t), allocatable :: mass_scheme
        !> Rayleigh damping of the continuum C = a0 M_alpha + a1 K_alpha: a0 [1/s], a1 [s].
        real(wp) :: rayleigh(2) = 0.0_wp
        !> Gravity acting on the continuum, weighted by alpha [m/s^2].
        real(wp) :: gravity(2) = 0.0_wp
        !> Gauss points per direction in the elements that meet the overlap.
        integer :: order = 4
        !> Bytes the dense multiplier matrices may take (coupled_step's multiplier_bytes; the
        !> memory available; < 0: no limit).
        integer(i8) :: memory_limit = -1_i8
    end type coupling2d_config_t

contains

    !> Build the coupled system of a continuum and disks (see the module description).
    subroutine build_coupled2d(config, model, dem, sys, error, beta, gamma, u0, v0, notice)
        !> The coupling.
        type(coupling2d_config_t), intent(in) :: config
        !> The continuum (materials, supports and loads set; no body force: `config%gravity`).
        type(continuum_model_t), intent(in) :: model
        !> The discrete domain (unweighted, before mj_init).
        type(dem_system_t), intent(in) :: dem
        !> The coupled system built.
        type(coupled_system_t), intent(out) :: sys
        !> Set on an invalid description, a disk in the FE-only zone, no coupled disk, a
        !> coupled centre in no element, or a singular multiplier matrix.
        type(error_t), allocatable, intent(out) :: error
        !> Newmark beta and gamma (default 1/4, 1/2).
        real(wp), intent(in), optional :: beta, gamma
        !> Initial displacements and velocities of the free dofs (default 0).
        real(wp), intent(in), optional :: u0(:), v0(:)
        !> Where a long set-up of the multiplier matrices is announced (default: silent).
        procedure(notice_iface), optional :: notice
        type(fem_triplets_t) :: k_all, m_all
        type(continuum_dynamics_t) :: ops
        type(element_grid_t) :: grid
        type(continuum_operator_t) :: op
        type(mediator_space_t) :: med
        class(multiplier_space_t), allocatable :: space
        real(wp), allocatable :: load(:), g_nodes(:), mg(:), uf(:), vf(:)
        class(mass_scheme_t), allocatable :: mass
        integer :: a
        if (.not. (config%thickness > 0)) then
            call make_error(error, 'coupling: thickness (out-of-plane depth of the particle domain) must be > 0')
            return
        end if
        if (.not. allocated(config%region)) then
            call make_error(error, 'coupling: no overlap region')
            return
        end if
        if (dem%particles%n == 0) then
            call make_error(error, 'coupling: the particle domain has no disk')
            return
        end if
        ! Weighted matrices and loads of the continuum.
        if (allocated(config%mass_scheme)) then
            allocate (mass, source=config%mass_scheme)
        else
            allocate (consistent_mass_t :: mass)
        end if
        call assemble_weighted(model, config%region, k_all, m_all, error, mass=mass, order=config%order)
        if (allocated(error)) return
        allocate (g_nodes(model%dof_count()), mg(model%dof_count()))
        do a = 1, model%mesh%node_count()
            g_nodes(2*a - 1:2*a) = config%gravity
        end do
        call m_all%matvec(g_nodes, mg)
        load = model%load + mg
        call ops%build_from(model, k_all, m_all, load, mass, config%rayleigh(1), config%rayleigh(2), error)
        if (allocated(error)) return
        ! Disks: weights, coupled ones, none in the FE-only zone.
        sys%dem = dem
        sys%thickness = config%thickness
        sys%condensed = config%condensed_contacts
        sys%weight = config%region%ramp()
        call config%region%select_disks(dem%particles%x(:dem%particles%n), dem%particles%y(:dem%particles%n), &
                                        sys%coupled, sys%alpha)
        call build_element_grid(model%mesh, grid)
        call check_fe_zone(error)
        if (allocated(error)) return
        call check_particle_sides(error)
        if (allocated(error)) return
        if (size(sys%coupled) == 0) then
            call make_error(error, 'coupling: no disk centre lies in the overlap: nothing to couple; check the '// &
                            'overlap region against the positions of the disks')
            return
        end if
        call build_continuum_operator(model, grid, dem%particles%x(sys%coupled), dem%particles%y(sys%coupled), op, &
                                      error, with_rotation=config%rotation_row)
        if (allocated(error)) return
        if (config%multipliers == multipliers_nodes) then
            call build_mediator2d(model, op, config%pairing, config%h1_length, med, sys%mediator_nodes, error)
            if (allocated(error)) return
            allocate (space, source=med)
        else
            call disk_space(op, space)
        end if
        allocate (uf(ops%n_free), vf(ops%n_free), source=0.0_wp)
        if (present(u0)) uf = u0
        if (present(v0)) vf = v0
        allocate (sys%model, source=ops)
        allocate (sys%op, source=op)
        call complete_coupled_system(sys, space, uf, vf, error, beta, gamma, config%memory_limit, notice)

    contains

        !> Error for a disk outside the overlap whose centre lies in an element.
        subroutine check_fe_zone(error)
            type(error_t), allocatable, intent(out) :: error
            real(wp) :: xi(2)
            integer :: i, e
            character(len=300) :: buf
            do i = 1, dem%particles%n
                if (sys%alpha(i) > 0) cycle
                call grid%locate(model%mesh, dem%particles%x(i), dem%particles%y(i), e, xi)
                if (e == 0) cycle
                write (buf, '(a,i0,a,es13.5e3,a,es13.5e3,a)') 'coupling: disk ', i, ' at (', &
                    dem%particles%x(i), ', ', dem%particles%y(i), ') m lies in '
                call make_error(error, trim(buf)//' '//model%mesh%element_label(e)// &
                                ' outside the overlap (the FE-only zone, where the continuum has its full weight): '// &
                                'remove the disk, or extend the overlap region over it')
                return
            end do
        end subroutine check_fe_zone

        !> Error for a particle-side edge along which the continuum goes on outside every
        !> region: alpha would jump there from alpha_min to 1 (the FE-only zone), the disks'
        !> weight from 1 - alpha_min to 0. The FE and particle sides swapped (a box with
        !> `right left` for `left right`) gave such a jump and was accepted. The field's probes
        !> just outside its particle-side edges (`weight_field_t%particle_side_probes`) tell.
        subroutine check_particle_sides(error)
            type(error_t), allocatable, intent(out) :: error
            real(wp), allocatable :: q(:, :)
            integer, allocatable :: edge(:), region(:)
            real(wp) :: xi(2)
            integer :: j, e
            character(len=800) :: buf
            call config%region%particle_side_probes(q, edge, region)
            do j = 1, size(edge)
                if (config%region%alpha_fe(q(1, j), q(2, j)) < 1.0_wp) cycle
                call grid%locate(model%mesh, q(1, j), q(2, j), e, xi)
                if (e == 0) cycle
                write (buf, '(a,i0,a,es13.5e3,a,es13.5e3,a)') 'the particle side (edge ', edge(j), &
                    ') of this region borders the continuum outside the overlap (at (', q(1, j), ', ', q(2, j), &
                    ') m, in '
                buf = trim(buf)//' '//model%mesh%element_label(e)//'), where alpha = 1: the weight would '// &
                      'jump there from alpha_min to 1; the particle side faces the particles only (no '// &
                      'continuum beyond it): are the FE and particle sides swapped?'
                if (region(j) > 0) then
                    write (buf, '(a,i0,a)') 'region ', region(j), ': '//trim(buf)
                end if
                call make_error(error, 'coupling: '//trim(buf))
                return
            end do
        end subroutine check_particle_sides
    end subroutine build_coupled2d
end module coupling_arlequin2d
