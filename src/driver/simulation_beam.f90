!> Beam (finite-element frame) runs of a [beam] deck without [particles]: what the static,
!> modal and dynamic analyses share, the frame and its model built from the deck. Each
!> analysis is an extension in its own module (driver_simulation_beam_static, _modal and
!> _dynamic); `driver_simulations` picks it from `[run] analysis`.
module driver_simulation_beam
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use core_kinds, only: wp, i8
    use core_error, only: error_t, make_input_error
    use core_strings, only: string_t, to_str
    use io_deck, only: deck_t
    use fem_beam_config, only: beam_config_t
    use fem_beam_model, only: beam_model_t, build_beam_model
    use driver_config, only: run_config_t, build_config
    use driver_results, only: results_writer_t
    use driver_simulation, only: simulation_t
    use driver_run_kind, only: check_particle_keywords_unused
    use driver_model_size, only: size_estimate_t, model_size_t
    implicit none
    private
    public :: beam_simulation_t, beam_setup, check_initial_energy, add_beam_size

    !> A planar frame run; its analysis is the extension.
    type, abstract, extends(simulation_t) :: beam_simulation_t
        !> Frame description from the deck.
        type(beam_config_t) :: beam
        !> Assembled model.
        type(beam_model_t) :: model
    contains
        !> See `simulation_t%describe`.
        procedure :: describe => beam_describe
        !> See `simulation_t%checkpoint_kind`: none (the dynamic analysis writes them).
        procedure :: checkpoint_kind => beam_checkpoint_kind
        !> See `simulation_t%has_time_loop`: no (the dynamic analysis has one).
        procedure :: has_time_loop => beam_has_time_loop
        !> See `simulation_t%check_deck`: no particle settings.
        procedure :: check_deck => beam_check_deck
        !> See `simulation_t%deck_warnings`: none.
        procedure :: deck_warnings => beam_deck_warnings
        !> See `simulation_t%size_estimate`: the frame's nodes and elements (`add_beam_size`).
        procedure :: size_estimate => beam_size_estimate
        !> Write the nodes and the elements into the results file.
        procedure :: write_mesh => beam_write_mesh
    end type beam_simulation_t

contains

    !> Settings and model from the deck, the start of every analysis' `init` (which adds what
    !> its analysis checks).
    subroutine beam_setup(self, deck, error)
        !> The simulation.
        class(beam_simulation_t), intent(inout) :: self
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> Set on any input error.
        type(error_t), allocatable, intent(out) :: error
        call build_config(deck, self%settings, self%beam, error)
        if (allocated(error)) return
        call build_beam_model(self%beam, self%model, error)
        if (allocated(error)) error%message = deck%file//': '//error%message
    end subroutine beam_setup

    !> 'static analysis'.
    function beam_describe(self) result(text)
        !> The simulation.
        class(beam_simulation_t), intent(in) :: self
        !> Summary.
        character(len=:), allocatable :: text
        text = self%settings%analysis//' analysis'
    end function beam_describe

    !> '': static and modal analyses write no checkpoint.
    function beam_checkpoint_kind(self) result(kind)
        !> The simulation.
        class(beam_simulation_t), intent(in) :: self
        !> Kind of run of its checkpoints.
        character(len=:), allocatable :: kind
        kind = ''
    end function beam_checkpoint_kind

    !> False: static and modal analyses have no time steps.
    pure logical function beam_has_time_loop(self)
        !> The simulation.
        class(beam_simulation_t), intent(in) :: self
        beam_has_time_loop = .false.
    end function beam_has_time_loop

    !> Error for particle-only keywords in a beam deck.
    subroutine beam_check_deck(self, deck, error)
        !> The simulation.
        class(beam_simulation_t), intent(in) :: self
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> Error naming the first such keyword, if any.
        type(error_t), allocatable, intent(out) :: error
        call check_particle_keywords_unused(deck, error)
    end subroutine beam_check_deck

    !> No warning.
    function beam_deck_warnings(self, deck) result(warnings)
        !> The simulation.
        class(beam_simulation_t), intent(in) :: self
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> None.
        type(string_t), allocatable :: warnings(:)
        allocate (warnings(0))
    end function beam_deck_warnings

    !> See `add_beam_size`.
    subroutine beam_size_estimate(self, deck, estimate, error)
        !> The simulation (not yet initialised).
        class(beam_simulation_t), intent(in) :: self
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> The estimate, the frame added.
        type(size_estimate_t), intent(inout) :: estimate
        !> Never set (a frame's counts are numbered as they are read).
        type(error_t), allocatable, intent(out) :: error
        call add_beam_size(deck, estimate)
    end subroutine beam_size_estimate

    !> The frame's part of a memory estimate (a beam run's, a coupled run's): its nodes and
    !> elements, those given one by one and those of each `line` and `polar_line` record.
    subroutine add_beam_size(deck, estimate)
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> The estimate, the frame added.
        type(size_estimate_t), intent(inout) :: estimate
        integer :: k
        call estimate%add_count(model_size_t(beam_nodes=int(deck%count('beam', 'node'), i8), &
                                             beam_elements=int(deck%count('beam', 'element'), i8)))
        do k = 1, size(deck%entries)
            associate (e => deck%entries(k))
                if (e%section /= 'beam') cycle
                if (e%keyword /= 'line' .and. e%keyword /= 'polar_line') cycle
                call estimate%add_record(model_size_t(beam_nodes=int(e%int('elements'), i8) + 1, &
                                                      beam_elements=int(e%int('elements'), i8)), k, e)
            end associate
        end do
    end subroutine add_beam_size

    !> The frame's nodes and elements into the results file.
    subroutine beam_write_mesh(self, out, error)
        !> The simulation.
        class(beam_simulation_t), intent(in) :: self
        !> The results file.
        type(results_writer_t), intent(inout) :: out
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        call out%beam%write_mesh(out%file, self%beam%node_id, self%beam%x, self%beam%y, self%beam%conn, error)
    end subroutine beam_write_mesh

    !> The kinetic energy 1/2 v.M v of the [initial] velocities and the strain energy
    !> 1/2 u.K u of the [initial] displacements must be finite: a velocity of 1e300 m/s or a
    !> displacement of 1e300 m stopped the run at step 0 on a value that is not finite.
    subroutine check_initial_energy(deck, run, model, error)
        !> The deck (for messages).
        type(deck_t), intent(in) :: deck
        !> Run settings (initial displacements and velocities).
        type(run_config_t), intent(in) :: run
        !> The beam model (weighted in a coupled run).
        type(beam_model_t), intent(in) :: model
        !> Set when an energy is not finite.
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: u0(:), v0(:)
        character(len=:), allocatable :: keyword
        integer :: at
        call model%restrict(run%v0, v0)
        if (.not. ieee_is_finite(model%kinetic_energy(v0))) then
            keyword = 'velocity'
            at = deck%line('initial', 'velocity')
            if (at == 0) then
                keyword = 'rigid'
                at = deck%line('initial', 'rigid')
            end if
            call make_input_error(error, deck%file, at, keyword, 'the kinetic energy 1/2 v.M v of the [initial] '// &
                                  'velocities is beyond the range of double precision (largest velocity '// &
                                  to_str(maxval(abs(v0)))//'): check their values (and the sections'' densities)')
            return
        end if
        call model%restrict(run%u0, u0)
        if (.not. ieee_is_finite(model%strain_energy(u0))) then
            call make_input_error(error, deck%file, deck%line('initial', 'displacement'), 'displacement', &
                                  'the strain energy 1/2 u.K u of the [initial] displacements is beyond the range '// &
                                  'of double precision (largest displacement '//to_str(maxval(abs(u0)))// &
                                  '): check their values (and the sections'' stiffness)')
        end if
    end subroutine check_initial_energy
end module driver_simulation_beam
