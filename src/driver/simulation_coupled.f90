!> Coupled (Arlequin) runs: a deck with [beam], [particles] and [coupling].
!>
!> `init` does everything that can fail because of the input (before the results folder is
!> touched); the time loop is driver_coupled_loop's. Results: the beam's fields in /fem, the
!> disks' in /dem, the multipliers, residuals and energy audit in /coupling (doc/output.md).
!> After every step the beam is checked as in the uncoupled runs (driver_guards): non-finite
!> displacements, velocities, accelerations or energy accounts.
module driver_simulation_coupled
    use core_kinds, only: wp, i8
    use core_error, only: error_t, make_input_error
    use core_strings, only: counted, to_str
    use io_deck, only: deck_t
    use fem_beam_config, only: beam_config_t
    use fem_beam_model, only: beam_model_t
    use fem_newmark, only: model_out_of_range
    use coupling_arlequin, only: coupled_system_t, build_coupled_system, coupled_beam
    use driver_config, only: run_config_t, build_config
    use driver_config_dem, only: dem_config_t, build_dem_config
    use driver_config_coupling, only: coupled_setup_t, build_coupling_config
    use driver_results, only: results_writer_t
    use driver_results_coupled, only: write_beam_overlap
    use driver_guards, only: check_beam_state
    use driver_simulation, only: report_iface
    use driver_simulation_beam, only: check_initial_energy, add_beam_size
    use driver_simulation_dem, only: add_particles_size
    use driver_model_size, only: size_estimate_t
    use driver_coupled_loop, only: arlequin_simulation_t
    use driver_coupled_rolling, only: free_rolling_warning
    use driver_displacement_scale, only: largest_displacement, model_extent, large_displacement_warning
    implicit none
    private
    public :: coupled_simulation_t, build_coupled

    !> A beam and particles glued in an overlap.
    type, extends(arlequin_simulation_t) :: coupled_simulation_t
        !> Frame description.
        type(beam_config_t) :: beam
        !> Particles, walls, contact laws and solver settings.
        type(dem_config_t) :: dem
        !> Coupling description from the deck.
        type(coupled_setup_t) :: coupling
        !> The weighted beam of the coupled system (constant), to expand the free DOFs to the
        !> nodes.
        type(beam_model_t) :: model
        !> Largest displacement of the stored states, their mean translation removed [m]
        !> (driver_displacement_scale: a units check at the end of the run).
        real(wp) :: u_max = 0.0_wp
    contains
        !> See `simulation_t%init`.
        procedure :: init => coupled_init
        !> See `simulation_t%describe`.
        procedure :: describe => coupled_describe
        !> See `simulation_t%size_estimate`: the beam's and the particles' parts.
        procedure :: size_estimate => coupled_size_estimate
        !> See `simulation_t%checkpoint_kind`.
        procedure :: checkpoint_kind => coupled_checkpoint_kind
        !> See `arlequin_simulation_t%particle_output`.
        procedure :: particle_output => coupled_particle_output
        !> See `arlequin_simulation_t%begin`.
        procedure :: begin => coupled_begin
        !> See `arlequin_simulation_t%check_part`.
        procedure :: check_part => coupled_check_part
        !> See `arlequin_simulation_t%store_part`.
        procedure :: store_part => coupled_store_part
        !> See `arlequin_simulation_t%unconverged_detail`.
        procedure :: unconverged_detail => coupled_unconverged_detail
        !> See `arlequin_simulation_t%summary_lines`.
        procedure :: summary_lines => coupled_summary_lines
    end type coupled_simulation_t

contains

    !> The beam's part and the particles' (driver_simulation_beam::add_beam_size,
    !> driver_simulation_dem::add_particles_size).
    subroutine coupled_size_estimate(self, deck, estimate, error)
        !> The simulation (not yet initialised).
        class(coupled_simulation_t), intent(in) :: self
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> The estimate, both parts added.
        type(size_estimate_t), intent(inout) :: estimate
        !> Never set (neither part can fail).
        type(error_t), allocatable, intent(out) :: error
        call add_beam_size(deck, estimate)
        call add_particles_size(deck, estimate)
    end subroutine coupled_size_estimate

    !> Both models and the coupled system; everything that can fail because of the input
    !> (library errors are attached to the [coupling] overlap line).
    subroutine coupled_init(self, deck, report, error)
        !> The simulation.
        class(coupled_simulation_t), intent(inout) :: self
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> Where the coupling's warnings go.
        procedure(report_iface) :: report
        !> Set on any input error.
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: message
        integer :: i
        call build_config(deck, self%settings, self%beam, error)
        if (allocated(error)) return
        call build_dem_config(deck, self%settings, self%beam%functions, self%dem, error)
        if (allocated(error)) return
        do i = 1, size(self%dem%warnings)
            call report(self%dem%warnings(i)%s)
        end do
        call build_coupling_config(deck, self%settings, self%beam, self%dem, self%coupling, error)
        if (allocated(error)) return
        do i = 1, size(self%coupling%warnings)
            call report(self%coupling%warnings(i)%s)
        end do
        allocate (self%sys)
        call build_coupled(self%settings, self%beam, self%dem, self%coupling, self%sys, report, error)
        if (allocated(error)) then
            message = error%message
            if (index(message, model_out_of_range) == 1) then
                ! The beam's Newmark step refused (fem_newmark): no step resolves the beam.
                call make_input_error(error, deck%file, deck%line('beam', 'section'), 'section', message)
            else if (index(message, 'omega_max h') > 0) then
                ! The beam's Newmark step refused (fem_newmark, round-off of the implicit step).
                call make_input_error(error, deck%file, deck%line('time', 'step'), 'step', message)
            else
                call make_input_error(error, deck%file, self%coupling%overlap_line, 'overlap', message)
            end if
            return
        end if
        message = free_rolling_warning(deck, self%coupling%config%rotation_row, self%sys%coupled, self%dem%system, &
                                       self%dem%material_id)
        if (len(message) > 0) call report(message)
        call coupled_beam(self%sys, self%model, error)
        if (allocated(error)) return
        call check_initial_energy(deck, self%settings, self%model, error)
        if (allocated(error)) return
        self%fclib_step = self%dem%fclib_step
    end subroutine coupled_init

    !> Build the coupled system of a deck (weighted beam, weighted disks, coupling operator,
    !> factored multiplier matrix). Errors come from the coupling library, without a deck
    !> line (the caller attaches one).
    subroutine build_coupled(run, beam, dem, setup, sys, report, error)
        !> Run settings (time step, Newmark beta and gamma, initial beam state).
        type(run_config_t), intent(in) :: run
        !> The beam (unweighted).
        type(beam_config_t), intent(in) :: beam
        !> The particles (unweighted, before mj_init).
        type(dem_config_t), intent(in) :: dem
        !> The coupling.
        type(coupled_setup_t), intent(in) :: setup
        !> The coupled system.
        type(coupled_system_t), intent(out) :: sys
        !> Where a long set-up is announced.
        procedure(report_iface) :: report
        !> Set when the library refuses the model.
        type(error_t), allocatable, intent(out) :: error
        if (allocated(run%u0) .and. allocated(run%v0)) then
            call build_coupled_system(setup%config, beam, dem%system, sys, error, &
                                      beta=run%beta, gamma=run%gamma, fe_u0=run%u0, fe_v0=run%v0, notice=report)
        else
            call build_coupled_system(setup%config, beam, dem%system, sys, error, &
                                      beta=run%beta, gamma=run%gamma, notice=report)
        end if
    end subroutine build_coupled

    !> 'coupled dynamic analysis, 11 beam nodes, 40 disks, 12 coupled'.
    function coupled_describe(self) result(text)
        !> The simulation.
        class(coupled_simulation_t), intent(in) :: self
        !> Summary.
        character(len=:), allocatable :: text
        text = 'coupled '//self%settings%analysis//' analysis, '//counted(size(self%beam%x), 'beam node')//', '// &
               counted(self%dem%system%particles%n, 'disk')//', '//to_str(self%sys%op%n_points)//' coupled'
    end function coupled_describe

    !> 'coupled'.
    function coupled_checkpoint_kind(self) result(kind)
        !> The simulation.
        class(coupled_simulation_t), intent(in) :: self
        !> Kind of run of its checkpoints.
        character(len=:), allocatable :: kind
        kind = 'coupled'
    end function coupled_checkpoint_kind

    !> The particle materials and contact storage of the deck.
    subroutine coupled_particle_output(self, material_id, store_contacts)
        !> The simulation.
        class(coupled_simulation_t), intent(in) :: self
        !> Deck id of each particle material.
        integer, allocatable, intent(out) :: material_id(:)
        !> Whether the contacts are stored with each output.
        logical, intent(out) :: store_contacts
        material_id = self%dem%material_id
        store_contacts = self%dem%store_contacts
    end subroutine coupled_particle_output

    !> The beam's mesh and its overlap with the disks.
    subroutine coupled_begin(self, out, error)
        !> The simulation.
        class(coupled_simulation_t), intent(inout) :: self
        !> The results file.
        type(results_writer_t), intent(inout) :: out
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        call out%beam%write_mesh(out%file, self%beam%node_id, self%beam%x, self%beam%y, self%beam%conn, error)
        if (allocated(error)) return
        call write_beam_overlap(out%file, self%sys, error)
    end subroutine coupled_begin

    !> Finite beam displacements, velocities, accelerations and energy accounts.
    subroutine coupled_check_part(self, k, error)
        !> The simulation.
        class(coupled_simulation_t), intent(in) :: self
        !> Steps done.
        integer(i8), intent(in) :: k
        !> Set at the first non-finite value.
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: d(:, :), v(:, :), a(:, :)
        call nodal_state(self, d, v, a)
        associate (fe => self%sys%fe)
            call check_beam_state(k, fe%t, self%beam%node_id, d, v, a, &
                                  [fe%kinetic, fe%strain, fe%external_work, fe%damping_dissipation], error)
        end associate
    end subroutine coupled_check_part

    !> The beam's displacements, velocities and accelerations at the nodes.
    subroutine coupled_store_part(self, out, error)
        !> The simulation.
        class(coupled_simulation_t), intent(inout) :: self
        !> The results file.
        type(results_writer_t), intent(inout) :: out
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: d(:, :), v(:, :), a(:, :)
        call nodal_state(self, d, v, a)
        self%u_max = max(self%u_max, largest_displacement(d(1:2, :) - spread(sum(d(1:2, :), dim=2)/size(d, 2), 2, size(d, 2))))
        call out%beam%append_state(out%file, self%sys%fe%t, d, v, a, error)
    end subroutine coupled_store_part

    !> Displacements, velocities and accelerations (3, n_nodes) of the beam.
    subroutine nodal_state(self, d, v, a)
        type(coupled_simulation_t), intent(in) :: self
        real(wp), allocatable, intent(out) :: d(:, :), v(:, :), a(:, :)
        allocate (d(3, self%model%n_nodes), v(3, self%model%n_nodes), a(3, self%model%n_nodes))
        call self%model%expand(self%sys%fe%u, d)
        call self%model%expand(self%sys%fe%v, v)
        call self%model%expand(self%sys%fe%a, a)
    end subroutine nodal_state

    !> ' (error ... > tolerance ...); the constraint q = C u still holds'.
    function coupled_unconverged_detail(self) result(text)
        !> The simulation.
        class(coupled_simulation_t), intent(in) :: self
        !> Text after 'sweeps'.
        character(len=:), allocatable :: text
        character(len=128) :: buf
        write (buf, '(a,es10.2e3,a,es10.2e3,a)') ' (error ', self%sys%stats%nlgs_error, ' > tolerance ', &
            self%sys%dem%solver%tol, '); the constraint q = C u still holds'
        text = trim(buf)
    end function coupled_unconverged_detail

    !> Model, constraint residuals, unconverged steps and the solver's limits.
    subroutine coupled_summary_lines(self, n_steps, unconverged, report)
        !> The simulation.
        class(coupled_simulation_t), intent(in) :: self
        !> Steps done.
        integer(i8), intent(in) :: n_steps
        !> Unconverged steps.
        integer, intent(in) :: unconverged
        !> Where the lines go.
        procedure(report_iface) :: report
        character(len=:), allocatable :: warning
        call report(self%run_line(counted(self%model%n_nodes, 'beam node'), n_steps))
        if (self%sys%on_nodes) then
            ! Only the projection on the mediator space is imposed: the per-disk residual from
            ! the coordinates is free in the kernel of Pi.
            call report(self%constraint_line('constraint (multipliers on the nodes): max |Pi (q - C u)|', &
                                             'per disk, from the coordinates'))
        else
            call report(self%constraint_line('constraint: max |q - C u|', 'from the coordinates'))
        end if
        call report('unconverged steps: '//to_str(unconverged)//' of '//to_str(n_steps)//' (tolerance '// &
                    to_str(self%sys%dem%solver%tol)//', at most '//to_str(self%sys%dem%solver%max_sweeps)//' sweeps)')
        warning = large_displacement_warning(self%u_max, model_extent(self%model%x, self%model%y), &
                                             '[beam] section, load, distributed, gravity, line, node, [particles]')
        if (len(warning) > 0) call report(warning)
    end subroutine coupled_summary_lines
end module driver_simulation_coupled
