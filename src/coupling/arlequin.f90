!> Arlequin coupling of a planar beam and disks (doc/theory.md section 6): the beam builder of
!> the coupled system. The coupled time step, the energy audit and the generic parts of the
!> build are in coupling_coupled_step (shared with the 2D continuum, coupling_arlequin2d);
!> this module re-exports them, so that callers keep using coupling_arlequin.
!>
!> Multiplier space (`multipliers`): one multiplier per coupled DOF (`multipliers_particles`,
!> the reference work: every coupled disk centre follows C u), or on the beam nodes that carry
!> coupled points (`multipliers_nodes`, a coarser mediator space, coupling_operator's
!> `build_mediator`). A disk may then move relative to the beam in the kernel of Pi (e.g. a
!> zig-zag between the nodes).
!>
!> Build (`build_coupled_system`): the beam is assembled with the weight alpha(s) (mass,
!> stiffness and self-weight integrated with alpha; its nodal and distributed loads in full);
!> every disk gets the weight alpha at the abscissa of its centre (fem_beam_projection: the
!> nearest point of the beam's axis, continued straight past the beam's ends; the projection
!> C is built with) and its mass and inertia are scaled by (1 - alpha),
!> its loads applied in full (alpha = 0 beyond the overlap: unchanged; a disk in the FE-only
!> zone, alpha = 1, is an error). A load is given to one model only, the other carries no
!> share of it: weighting it would drop the other share. The coupled disks are those
!> whose centre lies in the overlap (optionally within `max_offset` of the axis, or an explicit
!> list); C interpolates the beam at their centres (offset included, optional rotation row).
!> `coupled_beam` and `coupled_beam_operator` give back the beam and its C from a system built
!> here.
module coupling_arlequin
    use core_kinds, only: wp, i8
    use core_error, only: error_t, make_error, make_internal_error
    use fem_beam_config, only: beam_config_t
    use fem_beam_model, only: beam_model_t, build_beam_model
    use fem_beam_projection, only: beam_point_t, project_on_beam
    use dem_moreau_jean, only: dem_system_t
    use coupling_weights, only: weight_config_t, make_weight
    use coupling_operator, only: coupling_operator_t, build_coupling_operator, mediator_t, &
                                 build_mediator
    use coupling_multiplier_space, only: multiplier_space_t, mediator_space_t, make_mediator_space
    use coupling_coupled_step, only: coupled_system_t, coupled_stats_t, coupled_energies_t, &
                                     complete_coupled_system, disk_space, arlequin_step, notice_iface, &
                                     coupled_energies, coordinate_residual, multipliers_particles, &
                                     multipliers_nodes
    implicit none
    private
    public :: coupling_config_t, coupled_system_t, coupled_stats_t, coupled_energies_t
    public :: build_coupled_system, arlequin_step, coupled_energies, coordinate_residual
    public :: multipliers_particles, multipliers_nodes
    public :: coupled_beam, coupled_beam_operator

    !> Description of the coupling, as read from the deck ([coupling] section).
    type :: coupling_config_t
        !> Overlap interval [s_fe, s_particle] along the beam, weight shape and floor.
        type(weight_config_t) :: weight
        !> Out-of-plane thickness of the particle domain [m] (the DEM is per unit thickness;
        !> usually the width of the beam section). Required, > 0.
        real(wp) :: thickness = 0.0_wp
        !> Also couple the rotation of each coupled disk to the beam rotation, phi = theta(xi).
        logical :: rotation_row = .false.
        !> Couple only disks whose centre is at most this far from the beam axis [m]
        !> (<= 0: any distance).
        real(wp) :: max_offset = 0.0_wp
        !> Explicit list of coupled disks (indices); unallocated: every disk whose centre lies
        !> in the overlap (and within max_offset).
        integer, allocatable :: particles(:)
        !> Contacts on coupled disks use the condensed Delassus blocks (exact local solves);
        !> switch off only to compare convergence.
        logical :: condensed_contacts = .true.
        !> Multiplier space: multipliers_particles or multipliers_nodes.
        integer :: multipliers = multipliers_particles
        !> Bytes the dense multiplier matrices may take (coupled_step's multiplier_bytes; the
        !> memory available; < 0: no limit).
        integer(i8) :: memory_limit = -1_i8
    end type coupling_config_t

contains

    !> Build the coupled system from the descriptions of both domains (see the module
    !> description). The DEM system comes with disks at their reference positions, their
    !> physical masses and loads, materials, walls and settings (mj_init not called); the
    !> common time step is dem%scheme%h. The initial configuration is taken as consistent:
    !> the constraint is q - q_0 = C (u - u_0).
    subroutine build_coupled_system(config, beam, dem, sys, error, beta, gamma, fe_u0, fe_v0, notice)
        !> The coupling.
        type(coupling_config_t), intent(in) :: config
        !> The beam (unweighted description).
        type(beam_config_t), intent(in) :: beam
        !> The discrete domain (unweighted, before mj_init).
        type(dem_system_t), intent(in) :: dem
        !> The coupled system built.
        type(coupled_system_t), intent(out) :: sys
        !> Set on an invalid description, a disk in the FE-only zone, no coupled disk, or a
        !> singular multiplier matrix.
        type(error_t), allocatable, intent(out) :: error
        !> Newmark beta and gamma (default 1/4, 1/2: average acceleration, which makes the
        !> coupled energy balance exact with theta = 1/2).
        real(wp), intent(in), optional :: beta, gamma
        !> FE initial displacements and velocities per node (3, n_nodes) (default 0).
        real(wp), intent(in), optional :: fe_u0(:, :), fe_v0(:, :)
        !> Where a long set-up of the multiplier matrices is announced (default: silent).
        procedure(notice_iface), optional :: notice
        type(beam_model_t) :: model
        type(coupling_operator_t) :: op
        class(multiplier_space_t), allocatable :: space
        real(wp), allocatable :: u0(:), v0(:), s(:), off(:), alpha_pts(:)
        if (.not. (config%thickness > 0)) then
            call make_error(error, 'coupling: thickness (out-of-plane depth of the particle '// &
                            'domain, usually the width of the beam section) must be > 0')
            return
        end if
        call make_weight(config%weight, sys%weight, error)
        if (allocated(error)) return
        call build_beam_model(beam, model, error, sys%weight)
        if (allocated(error)) return
        call check_beam_weight(sys, model, error)
        if (allocated(error)) return
        sys%dem = dem
        sys%thickness = config%thickness
        sys%condensed = config%condensed_contacts
        if (sys%dem%particles%n == 0) then
            call make_error(error, 'coupling: the particle domain has no disk')
            return
        end if
        call disk_weights(sys, model, s, off, error)
        if (allocated(error)) return
        call select_coupled(config, sys, off, error)
        if (allocated(error)) return
        if (config%max_offset > 0) then
            call build_coupling_operator(model, sys%dem%particles%x(sys%coupled), &
                                         sys%dem%particles%y(sys%coupled), op, error, &
                                         with_rotation=config%rotation_row, &
                                         max_offset=config%max_offset)
        else
            call build_coupling_operator(model, sys%dem%particles%x(sys%coupled), &
                                         sys%dem%particles%y(sys%coupled), op, error, &
                                         with_rotation=config%rotation_row)
        end if
        if (allocated(error)) return
        call op%point_weights(sys%weight, alpha_pts, error)
        if (allocated(error)) return
        call nodal_to_free(model, 'fe_u0', u0, error, fe_u0)
        if (allocated(error)) return
        call nodal_to_free(model, 'fe_v0', v0, error, fe_v0)
        if (allocated(error)) return
        call make_space(config, model, op, sys, space, error)
        if (allocated(error)) return
        allocate (sys%model, source=model)
        allocate (sys%op, source=op)
        call complete_coupled_system(sys, space, u0, v0, error, beta, gamma, config%memory_limit, notice)
    end subroutine build_coupled_system

    !> The multiplier space chosen by config%multipliers: per coupled DOF, or the mediator
    !> space on the beam nodes carrying coupled points (Pi from build_mediator).
    subroutine make_space(config, model, op, sys, space, error)
        type(coupling_config_t), intent(in) :: config
        type(beam_model_t), intent(in) :: model
        type(coupling_operator_t), intent(in) :: op
        type(coupled_system_t), intent(inout) :: sys
        class(multiplier_space_t), allocatable, intent(out) :: space
        type(error_t), allocatable, intent(out) :: error
        type(mediator_space_t) :: med
        type(mediator_t) :: mediator
        if (config%multipliers == multipliers_nodes) then
            call build_mediator(model, op, mediator, error)
            if (allocated(error)) return
            call make_mediator_space(mediator%pi, mediator%comp, med, error)
            if (allocated(error)) return
            allocate (space, source=med)
            sys%mediator_nodes = mediator%node
        else
            call disk_space(op, space)
        end if
    end subroutine make_space

    !> The weighted beam of a system built by `build_coupled_system` (a copy).
    subroutine coupled_beam(sys, model, error)
        !> The coupled system (beam and disks).
        type(coupled_system_t), intent(in) :: sys
        !> Its beam model.
        type(beam_model_t), intent(out) :: model
        !> Internal error when the system's FE model is not a beam (not built here).
        type(error_t), allocatable, intent(out) :: error
        select type (m => sys%model)
        type is (beam_model_t)
            model = m
        class default
            call make_internal_error(error, 'coupled_beam', 'the coupled system has no beam model '// &
                                     '(not built by build_coupled_system)')
        end select
    end subroutine coupled_beam

    !> The coupling operator of a system built by `build_coupled_system` (a copy).
    subroutine coupled_beam_operator(sys, op, error)
        !> The coupled system (beam and disks).
        type(coupled_system_t), intent(in) :: sys
        !> Its C.
        type(coupling_operator_t), intent(out) :: op
        !> Internal error when the system's C is not a beam's (not built here).
        type(error_t), allocatable, intent(out) :: error
        select type (o => sys%op)
        type is (coupling_operator_t)
            op = o
        class default
            call make_internal_error(error, 'coupled_beam_operator', 'the coupled system''s C is not a beam''s '// &
                                     '(not built by build_coupled_system)')
        end select
    end subroutine coupled_beam_operator

    !> Error when an element lies wholly where alpha = 0 (beyond the overlap's particle end):
    !> it would have neither mass nor stiffness.
    subroutine check_beam_weight(sys, model, error)
        type(coupled_system_t), intent(in) :: sys
        type(beam_model_t), intent(in) :: model
        type(error_t), allocatable, intent(out) :: error
        integer :: e
        character(len=300) :: buf
        do e = 1, model%n_elements
            if (sys%weight%value(model%abscissa_at(e, 1.0e-6_wp)) > 0 .or. &
                sys%weight%value(model%abscissa_at(e, 0.5_wp)) > 0 .or. &
                sys%weight%value(model%abscissa_at(e, 1 - 1.0e-6_wp)) > 0) cycle
            write (buf, '(a,i0,a,es13.5e3,a,es13.5e3,a,es13.5e3,a)') 'coupling: beam element ', e, &
                ' (abscissa ', model%abscissa_at(e, 0.0_wp), ' to ', &
                model%abscissa_at(e, 1.0_wp), ' m) lies beyond the overlap, where '// &
                'alpha = 0: it would have neither mass nor stiffness; end the beam at '// &
                's_particle = ', &
                sys%weight%s_particle, ' m'
            call make_error(error, trim(buf))
            return
        end do
    end subroutine check_beam_weight

    !> Nodal array (3, n_nodes) to a free-DOF vector (zeros when absent).
    subroutine nodal_to_free(model, what, v, error, d)
        type(beam_model_t), intent(in) :: model
        character(len=*), intent(in) :: what
        real(wp), allocatable, intent(out) :: v(:)
        type(error_t), allocatable, intent(out) :: error
        real(wp), intent(in), optional :: d(:, :)
        if (present(d)) then
            if (any(shape(d) /= [3, model%n_nodes])) then
                call make_internal_error(error, 'coupling', what//' must be given as (3, n_nodes)')
                return
            end if
        end if
        call model%restrict(d, v)
    end subroutine nodal_to_free

    !> Weight alpha of every disk at the abscissa of its centre and its signed offset from the
    !> axis (fem_beam_projection, as for C); a disk in the FE-only zone (alpha = 1) is an error.
    subroutine disk_weights(sys, model, s, off, error)
        type(coupled_system_t), intent(inout) :: sys
        type(beam_model_t), intent(in) :: model
        real(wp), allocatable, intent(out) :: s(:), off(:)
        type(error_t), allocatable, intent(out) :: error
        type(beam_point_t) :: at
        integer :: i, n
        character(len=300) :: buf
        n = sys%dem%particles%n
        allocate (s(n), off(n), sys%alpha(n))
        do i = 1, n
            at = project_on_beam(model, sys%dem%particles%x(i), sys%dem%particles%y(i))
            s(i) = at%abscissa
            off(i) = at%offset()
            sys%alpha(i) = sys%weight%value(s(i))
            if (sys%alpha(i) < 1) cycle
            write (buf, '(a,i0,a,es13.5e3,a,es13.5e3,a,es13.5e3,a)') 'coupling: disk ', i, ' at (', &
                sys%dem%particles%x(i), ', ', sys%dem%particles%y(i), ') m (abscissa ', s(i), &
                ' m) lies in the FE-only zone (alpha = 1), where its weighted mass '// &
                '(1 - alpha) m would be zero; remove it or move the overlap so that it covers '// &
                'the disk'
            call make_error(error, trim(buf))
            return
        end do
    end subroutine disk_weights

    !> The coupled disks: the explicit list, or every disk with 0 < alpha < 1 (centre in the
    !> overlap) within max_offset of the axis.
    subroutine select_coupled(config, sys, off, error)
        type(coupling_config_t), intent(in) :: config
        type(coupled_system_t), intent(inout) :: sys
        real(wp), intent(in) :: off(:)
        type(error_t), allocatable, intent(out) :: error
        logical, allocatable :: take(:)
        integer :: i, n
        character(len=160) :: buf
        n = sys%dem%particles%n
        if (allocated(config%particles)) then
            do i = 1, size(config%particles)
                if (config%particles(i) < 1 .or. config%particles(i) > n) then
                    write (buf, '(a,i0,a,i0,a)') 'coupling: coupled disk ', config%particles(i), &
                        ' does not exist (disks are numbered 1..', n, ')'
                else if (any(config%particles(:i - 1) == config%particles(i))) then
                    write (buf, '(a,i0,a)') 'coupling: disk ', config%particles(i), &
                        ' is listed twice among the coupled disks'
                else
                    cycle
                end if
                call make_error(error, trim(buf))
                return
            end do
            sys%coupled = config%particles
        else
            take = sys%alpha > 0 .and. sys%alpha < 1
            if (config%max_offset > 0) take = take .and. abs(off) <= config%max_offset
            sys%coupled = pack([(i, i=1, n)], take)
        end if
        if (size(sys%coupled) == 0) then
            call make_error(error, 'coupling: no disk centre lies in the overlap (within '// &
                            'max_offset of the beam axis): nothing to couple; check the overlap '// &
                            'interval against the positions of the disks')
        end if
    end subroutine select_coupled
end module coupling_arlequin
