!> Coupled continuum-disk runs: a deck with [continuum], [particles] and [coupling] (regions).
!>
!> The continuum part of the deck (mesh, materials, supports, loads, initial velocity, [time])
!> is read by the dynamic continuum run's own `init` (driver_simulation_continuum_dynamic) on
!> the deck without the particle sections, and the particle part by the particle run's `init`
!> (driver_simulation_dem) on the deck without [continuum]; every error keeps its file, line and
!> keyword. [coupling] is read by driver_config_coupling2d, and coupling_arlequin2d builds the
!> coupled system, whose time step (coupling_coupled_step's arlequin_step) is the beam's; the
!> time loop is driver_coupled_loop's.
!>
!> Results: /continuum (mesh, sets, displacement, velocity, centre stresses, and the FE side's
!> energies: kinetic and strain weighted by alpha), /dem and /coupling as in beam-coupled runs,
!> and, written by driver_run at the end as for every run (driver_results_xdmf), `<deck>.xdmf`
!> next to the HDF5 file with the mesh's fields and the disks per stored state. Checkpoints hold what a beam-particle coupled
!> run's hold (driver_checkpoint::save_coupled: the Newmark state of the continuum, the disks,
!> contacts and bonds, the multipliers and the constraint state) under the kind 'coupled2d';
!> at a restart the continuum writer counts its stored states in the results file.
module driver_simulation_coupled2d
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use core_kinds, only: wp, i8
    use core_error, only: error_t, make_error, make_input_error, make_internal_error
    use core_strings, only: counted, to_str
    use io_deck, only: deck_t
    use io_hdf5_file, only: h5_file_t
    use fem_continuum_dynamics, only: continuum_dynamics_t
    use coupling_coupled_step, only: coupled_energies_t, coupled_energies
    use coupling_fe_accounts, only: fe_whole_t
    use coupling_operator2d, only: continuum_operator_t
    use coupling_arlequin2d, only: build_coupled2d
    use driver_config_coupling2d, only: coupled2d_setup_t, build_coupling2d_config, check_coupled2d_scheme
    use driver_results, only: results_writer_t
    use driver_results_continuum, only: continuum_writer_t
    use driver_simulation, only: report_iface
    use driver_simulation_continuum_dynamic, only: continuum_dynamic_t
    use driver_simulation_dem, only: dem_simulation_t
    use driver_coupled_loop, only: arlequin_simulation_t
    use driver_coupled_rolling, only: free_rolling_warning
    use driver_checkpoint, only: read_finite_attribute
    use driver_displacement_scale, only: largest_displacement, model_extent, large_displacement_warning
    use driver_model_size, only: size_estimate_t
    implicit none
    private
    public :: coupled2d_simulation_t

    !> A 2D continuum and particles glued in overlap regions.
    type, extends(arlequin_simulation_t) :: coupled2d_simulation_t
        !> The continuum part (model, run settings, initial state).
        type(continuum_dynamic_t) :: continuum
        !> The particle part (disks, walls, contact laws, solver).
        type(dem_simulation_t) :: particles
        !> The coupling from the deck.
        type(coupled2d_setup_t) :: coupling
        !> Writer of /continuum.
        type(continuum_writer_t) :: fe_out
        !> Largest displacement of the stored states, their mean translation removed [m]
        !> (driver_displacement_scale: a units check at the end of the run).
        real(wp) :: u_max = 0.0_wp
    contains
        !> See `simulation_t%init`.
        procedure :: init => coupled2d_init
        !> See `simulation_t%describe`.
        procedure :: describe => coupled2d_describe
        !> See `simulation_t%size_estimate`: the continuum's part and the particles'.
        procedure :: size_estimate => coupled2d_size_estimate
        !> See `simulation_t%checkpoint_kind`.
        procedure :: checkpoint_kind => coupled2d_checkpoint_kind
        !> See `arlequin_simulation_t%particle_output`.
        procedure :: particle_output => coupled2d_particle_output
        !> See `arlequin_simulation_t%begin`.
        procedure :: begin => coupled2d_begin
        !> See `arlequin_simulation_t%after_step`.
        procedure :: after_step => coupled2d_after_step
        !> See `arlequin_simulation_t%check_part`.
        procedure :: check_part => coupled2d_check_part
        !> See `arlequin_simulation_t%store_part`.
        procedure :: store_part => coupled2d_store_part
        !> See `arlequin_simulation_t%unconverged_detail`.
        procedure :: unconverged_detail => coupled2d_unconverged_detail
        !> See `arlequin_simulation_t%summary_lines`.
        procedure :: summary_lines => coupled2d_summary_lines
        !> See `arlequin_simulation_t%save_part`.
        procedure :: save_part => coupled2d_save_part
        !> See `arlequin_simulation_t%check_saved_part`.
        procedure :: check_saved_part => coupled2d_check_saved_part
        !> See `arlequin_simulation_t%load_part`.
        procedure :: load_part => coupled2d_load_part
        !> See `simulation_t%inputs_text`: the continuum's mesh file.
        procedure :: inputs_text => coupled2d_inputs_text
    end type coupled2d_simulation_t

contains

    !> The continuum's part and the particles', as their own runs estimate them.
    subroutine coupled2d_size_estimate(self, deck, estimate, error)
        !> The simulation (not yet initialised).
        class(coupled2d_simulation_t), intent(in) :: self
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> The estimate, both parts added.
        type(size_estimate_t), intent(inout) :: estimate
        !> Set on a continuum mesh too large to number.
        type(error_t), allocatable, intent(out) :: error
        call self%continuum%size_estimate(deck, estimate, error)
        if (allocated(error)) return
        call self%particles%size_estimate(deck, estimate, error)
    end subroutine coupled2d_size_estimate

    !> Both models and the coupled system (library errors are attached to the first region line).
    subroutine coupled2d_init(self, deck, report, error)
        !> The simulation.
        class(coupled2d_simulation_t), intent(inout) :: self
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> Where warnings go.
        procedure(report_iface) :: report
        !> Set on any input error.
        type(error_t), allocatable, intent(out) :: error
        type(deck_t) :: part
        character(len=:), allocatable :: message
        integer :: i
        ! the analysis and the scheme first: the continuum's own checks would ask for changes
        ! (a lumped mass, a shorter step of central differences) that they refuse
        call check_coupled2d_scheme(deck, error)
        if (allocated(error)) return
        ! The continuum without particles, coupling and gravity (weighted by the coupling).
        part = without(deck, [character(len=24) :: 'particles', 'walls', 'contacts', 'solver', 'coupling', &
                              'time theta', 'output contacts', 'continuum gravity'])
        call self%continuum%init(part, report, error)
        if (allocated(error)) return
        self%settings = self%continuum%settings
        ! The particles without the continuum, the coupling and the FE time scheme.
        part = without(deck, [character(len=24) :: 'continuum', 'coupling', 'time scheme', 'time beta', &
                              'time gamma'])
        call self%particles%init(part, report, error)
        if (allocated(error)) return
        associate (p => self%particles%dem%system%particles)
            call build_coupling2d_config(deck, self%continuum%model, p%gravity, p%x(1:p%n), p%y(1:p%n), &
                                         self%coupling, error)
        end associate
        if (allocated(error)) return
        do i = 1, size(self%coupling%warnings)
            call report(self%coupling%warnings(i)%s)
        end do
        allocate (self%sys)
        call build_coupled2d(self%coupling%config, self%continuum%model, self%particles%dem%system, self%sys, error, &
                             beta=self%settings%beta, gamma=self%settings%gamma, u0=self%continuum%integ%u, &
                             v0=self%continuum%integ%v, notice=report)
        if (allocated(error)) then
            message = error%message
            if (index(message, 'A_m = Pi A Pi^T') > 0 .and. deck%has('coupling', 'h1_length')) then
                ! The H1 pairing scales the conditioning of A_m by about (l / element size)^4.
                call make_input_error(error, deck%file, deck%line('coupling', 'h1_length'), 'h1_length', &
                                      message//': the conditioning of A_m grows as (h1_length / element '// &
                                      'size)^4 with pairing = h1; lower h1_length (of the order of the '// &
                                      'element size)')
            else
                call make_input_error(error, deck%file, self%coupling%region_line, 'region', message)
            end if
            return
        end if
        message = free_rolling_warning(deck, self%coupling%config%rotation_row, self%sys%coupled, &
                                       self%particles%dem%system, self%particles%dem%material_id)
        if (len(message) > 0) call report(message)
        self%fclib_step = self%particles%dem%fclib_step
    end subroutine coupled2d_init

    !> The deck without the entries of the given sections or 'section keyword' pairs.
    function without(deck, names) result(part)
        type(deck_t), intent(in) :: deck
        character(len=*), intent(in) :: names(:)
        type(deck_t) :: part
        logical, allocatable :: keep(:)
        integer :: i
        allocate (keep(size(deck%entries)))
        do i = 1, size(deck%entries)
            associate (e => deck%entries(i))
                keep(i) = .not. (any(names == e%section) .or. any(names == e%section//' '//e%keyword))
            end associate
        end do
        part = deck
        part%entries = pack(deck%entries, keep)
    end function without

    !> 'coupled dynamic analysis of a continuum, 32 elements, 64 disks, 64 coupled'.
    function coupled2d_describe(self) result(text)
        !> The simulation.
        class(coupled2d_simulation_t), intent(in) :: self
        !> Summary.
        character(len=:), allocatable :: text
        text = 'coupled '//self%settings%analysis//' analysis of a continuum, '// &
               counted(self%continuum%model%mesh%element_count(), 'element')//', '// &
               counted(self%sys%dem%particles%n, 'disk')//', '//to_str(self%sys%op%n_points)//' coupled'
    end function coupled2d_describe

    !> 'coupled2d'.
    function coupled2d_checkpoint_kind(self) result(kind)
        !> The simulation.
        class(coupled2d_simulation_t), intent(in) :: self
        !> Kind of run of its checkpoints.
        character(len=:), allocatable :: kind
        kind = 'coupled2d'
    end function coupled2d_checkpoint_kind

    !> The particle materials and contact storage of the deck.
    subroutine coupled2d_particle_output(self, material_id, store_contacts)
        !> The simulation.
        class(coupled2d_simulation_t), intent(in) :: self
        !> Deck id of each particle material.
        integer, allocatable, intent(out) :: material_id(:)
        !> Whether the contacts are stored with each output.
        logical, intent(out) :: store_contacts
        material_id = self%particles%dem%material_id
        store_contacts = self%particles%dem%store_contacts
    end subroutine coupled2d_particle_output

    !> /continuum (mesh and sets), the mediator nodes; the continuum's audit started.
    subroutine coupled2d_begin(self, out, error)
        !> The simulation.
        class(coupled2d_simulation_t), intent(inout) :: self
        !> The results file.
        type(results_writer_t), intent(inout) :: out
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: region(:)
        integer :: r
        call self%fe_out%begin(out%file, self%continuum%model, error)
        if (.not. allocated(error)) call self%fe_out%begin_series(out%file, error)
        if (allocated(error)) return
        ! the region of each multiplier row (that of its disk's centre at t = 0), so that a
        ! region's resultant is the sum of its rows of /coupling/lambda
        associate (p => self%sys%dem%particles, owner => self%sys%rows%owner)
            allocate (region(size(owner)))
            do r = 1, size(owner)
                region(r) = self%coupling%config%region%region_of(p%x(owner(r)), p%y(owner(r)))
            end do
        end associate
        call out%file%write_dataset('/coupling/rows/region', region, error)
        if (allocated(error)) return
        if (size(self%sys%mediator_nodes) > 0) then
            call out%file%write_dataset('/coupling/mediator_nodes', self%sys%mediator_nodes, error)
            if (allocated(error)) return
        end if
        call audit_step(self, .true., error)
    end subroutine coupled2d_begin

    !> The continuum's audit advanced by the step just made.
    subroutine coupled2d_after_step(self, error)
        !> The simulation.
        class(coupled2d_simulation_t), intent(inout) :: self
        !> Internal error when the coupled system is not a continuum's.
        type(error_t), allocatable, intent(out) :: error
        call audit_step(self, .false., error)
    end subroutine coupled2d_after_step

    !> The continuum's audit of the whole body (prescribed dofs and reactions included) on
    !> the weighted operator: started (resumed with the totals of a checkpoint), or advanced
    !> by the step just made. The multipliers' force -C^T lambda on all dofs is the coupling
    !> force of the audit (its share on the prescribed dofs is taken by the supports, and so
    !> enters the reactions), and the audit's accounts are the FE side's in /coupling/energy.
    !> A system that coupling_arlequin2d did not build (its C or FE model another kind's) is
    !> an internal error.
    subroutine audit_step(self, first, error, totals)
        type(coupled2d_simulation_t), intent(inout) :: self
        logical, intent(in) :: first
        type(error_t), allocatable, intent(out) :: error
        real(wp), intent(in), optional :: totals(4)
        real(wp), allocatable :: fc(:)
        allocate (fc(size(self%continuum%model%prescribed)), source=0.0_wp)
        select type (op => self%sys%op)
        type is (continuum_operator_t)
            call op%transpose_all(self%sys%lambda, fc)
            fc = -fc
        class default
            call make_internal_error(error, 'coupled2d audit', 'the coupled system''s C is not a continuum''s')
            return
        end select
        associate (au => self%continuum%audit, w => self%sys%prescribed_coupling_work)
            select type (ops => self%sys%model)
            type is (continuum_dynamics_t)
                if (first .and. present(totals)) then
                    call au%resume(ops, self%continuum%model, self%sys%fe, totals, fc, -w)
                else if (first) then
                    call au%start(ops, self%continuum%model, self%sys%fe, fc, -w)
                else
                    call au%advance(ops, self%continuum%model, self%sys%fe, fc, -w)
                end if
            class default
                call make_internal_error(error, 'coupled2d audit', 'the coupled system''s FE model is not a '// &
                                         'continuum''s')
                return
            end select
            ! the FE side's accounts in the coupled audit are the whole body's
            deallocate (self%sys%accounts)
            allocate (self%sys%accounts, source=fe_whole_t(kinetic=au%kinetic, strain=au%strain, &
                                                           external_work=au%load_work, damping=au%damping, &
                                                           reaction_work=au%reaction_work, initial=au%initial))
        end associate
    end subroutine audit_step

    !> Finite continuum state and energy accounts (a checkpoint may follow: it must hold
    !> finite values).
    subroutine coupled2d_check_part(self, k, error)
        !> The simulation.
        class(coupled2d_simulation_t), intent(in) :: self
        !> Steps done.
        integer(i8), intent(in) :: k
        !> Set at the first non-finite value.
        type(error_t), allocatable, intent(out) :: error
        character(len=256) :: buf
        associate (fe => self%sys%fe)
            if (all(ieee_is_finite(fe%u)) .and. all(ieee_is_finite(fe%v)) .and. &
                all(ieee_is_finite([fe%kinetic, fe%strain, fe%external_work, fe%damping_dissipation, &
                                    fe%coupling_work]))) return
            write (buf, '(a,i0,a,es13.5e3,a)') 'coupled continuum: the state is not finite after step ', k, &
                ' (t = ', fe%t, ' s); likely cause: loads or moduli far out of scale'
        end associate
        call make_error(error, trim(buf))
    end subroutine coupled2d_check_part

    !> Displacements, velocities, centre stresses and the continuum's energies.
    subroutine coupled2d_store_part(self, out, error)
        !> The simulation.
        class(coupled2d_simulation_t), intent(inout) :: self
        !> The results file.
        type(results_writer_t), intent(inout) :: out
        !> Set on a non-finite stress or energy, or a write failure.
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: u(:), v(:), stress(:, :), szz(:), vm(:)
        type(coupled_energies_t) :: en
        character(len=256) :: buf
        integer :: n
        associate (sys => self%sys, model => self%continuum%model, au => self%continuum%audit)
            u = model%expand(sys%fe%u, sys%fe%t)
            v = model%expand(sys%fe%v, sys%fe%t, 1)
            n = model%mesh%node_count()
            call model%centre_stresses(u, stress, error)
            if (allocated(error)) return
            call model%stress_measures(stress, szz, vm)
            en = coupled_energies(sys)
            ! (von Mises squares the stresses: it is not finite beyond 1e154 Pa)
            if (.not. (all(ieee_is_finite(stress)) .and. all(ieee_is_finite(vm)) .and. ieee_is_finite(en%balance))) then
                write (buf, '(a,es13.5e3,a)') 'coupled continuum: a stress or an energy is not finite at t = ', &
                    sys%fe%t, ' s; likely cause: a time step far too large, or loads or moduli far out of scale'
                call make_error(error, trim(buf))
                return
            end if
            associate (un => reshape(u, [2, n]))
                self%u_max = max(self%u_max, largest_displacement(un - spread(sum(un, dim=2)/n, 2, n)))
            end associate
            call self%fe_out%store(out%file, sys%fe%t, reshape(u, [2, n]), reshape(v, [2, n]), stress, szz, vm, error)
            if (allocated(error)) return
            call self%fe_out%store_energy(out%file, sys%fe%t, au%kinetic, au%strain, au%load_work, au%damping, &
                                          au%balance(), error, au%reaction_work, au%reaction_resultant)
        end associate
    end subroutine coupled2d_store_part

    !> '; the constraint still holds'.
    function coupled2d_unconverged_detail(self) result(text)
        !> The simulation.
        class(coupled2d_simulation_t), intent(in) :: self
        !> Text after 'sweeps'.
        character(len=:), allocatable :: text
        text = '; the constraint still holds'
    end function coupled2d_unconverged_detail

    !> Model, constraint residuals, unconverged steps.
    subroutine coupled2d_summary_lines(self, n_steps, unconverged, report)
        !> The simulation.
        class(coupled2d_simulation_t), intent(in) :: self
        !> Steps done.
        integer(i8), intent(in) :: n_steps
        !> Unconverged steps.
        integer, intent(in) :: unconverged
        !> Where the lines go.
        procedure(report_iface) :: report
        character(len=:), allocatable :: warning
        call report(self%run_line(counted(self%continuum%model%mesh%element_count(), 'element'), n_steps))
        call report(self%constraint_line('constraint: max |Pi (q - C u)|', 'per disk, from the coordinates'))
        call report('unconverged steps: '//to_str(unconverged)//' of '//to_str(n_steps))
        associate (x => self%continuum%model%mesh%x)
            warning = large_displacement_warning(self%u_max, model_extent(x(1, :), x(2, :)), &
                                                 '[continuum] material, load, traction, gravity, displacement, '// &
                                                 'mesh, [particles]')
        end associate
        if (len(warning) > 0) call report(warning)
    end subroutine coupled2d_summary_lines

    !> The continuum's accumulated works (the rest of its audit follows from the state) and the
    !> multipliers' work through the prescribed dofs.
    subroutine coupled2d_save_part(self, f, error)
        !> The simulation.
        class(coupled2d_simulation_t), intent(in) :: self
        !> The checkpoint being written.
        type(h5_file_t), intent(inout) :: f
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        call f%write_attribute('/coupling', 'continuum_audit', &
                               [self%continuum%audit%totals(), self%sys%prescribed_coupling_work], error)
    end subroutine coupled2d_save_part

    !> The totals `save_part` wrote are finite (before the results file is cut back).
    subroutine coupled2d_check_saved_part(self, f, error)
        !> The simulation.
        class(coupled2d_simulation_t), intent(in) :: self
        !> The checkpoint (open).
        type(h5_file_t), intent(inout) :: f
        !> Set when the attribute is missing, of another size or not finite.
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: totals(:)
        call read_finite_attribute(f, '/coupling', 'continuum_audit', totals, 5, error)
    end subroutine coupled2d_check_saved_part

    !> The continuum's audit resumed with the totals of the checkpoint, C_p u_p at the restart
    !> time, and the continuum writer's count of stored states from the results file.
    subroutine coupled2d_load_part(self, f, out, error)
        !> The simulation.
        class(coupled2d_simulation_t), intent(inout) :: self
        !> The checkpoint (open).
        type(h5_file_t), intent(inout) :: f
        !> The results file (restored).
        type(results_writer_t), intent(inout) :: out
        !> Set on a read failure.
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: totals(:)
        call read_finite_attribute(f, '/coupling', 'continuum_audit', totals, 5, error)
        if (allocated(error)) return
        self%sys%prescribed_coupling_work = totals(5)
        call audit_step(self, .true., error, totals(1:4))
        if (allocated(error)) return
        self%sys%cp = 0.0_wp
        call self%sys%op%add_prescribed(self%sys%fe%t, 0, self%sys%cp)
        call self%fe_out%resume(out%file, self%continuum%model%mesh, error)
    end subroutine coupled2d_load_part

    !> See `simulation_t%inputs_text`: the continuum's Gmsh mesh file ('' for a generated mesh).
    function coupled2d_inputs_text(self) result(text)
        !> The simulation (after `init`).
        class(coupled2d_simulation_t), intent(in) :: self
        !> The mesh file's text.
        character(len=:), allocatable :: text
        text = self%continuum%inputs_text()
    end function coupled2d_inputs_text
end module driver_simulation_coupled2d
