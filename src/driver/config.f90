!> From a validated deck to the run settings `run_config_t` (what to compute and how), with the
!> checks across lines (time step against end time, modes against free DOFs, a lumped mass for
!> the central-difference scheme). The frame's configuration is read by driver_config_beam,
!> the time functions by driver_config_timefunc; `build_config` and `build_particles_config`
!> gather them for a run. Each error names the deck file, the line and the keyword concerned.
module driver_config
    use core_kinds, only: wp, i8
    use core_constants, only: relative_roundoff
    use core_error, only: error_t, make_input_error
    use core_strings, only: to_str
    use core_timefunc, only: time_function_slot_t
    use fem_beam_config, only: beam_config_t
    use fem_mass_scheme, only: mass_scheme_t, consistent_mass_t
    use io_deck, only: deck_t
    use driver_config_timefunc, only: build_time_functions
    use driver_config_beam, only: build_beam_config, build_initial
    implicit none
    private
    public :: run_config_t, build_config, build_particles_config, max_steps, build_run_settings, steps_to_end

    !> Largest number of time steps of a run. The step counter is 64-bit; the bound is that of
    !> the 32-bit step counts stored in the results file (/summary steps, /dem/solver).
    integer(i8), parameter :: max_steps = int(huge(0), i8)

    !> What to compute and how (everything but the model itself).
    type :: run_config_t
        !> Title of the run.
        character(len=:), allocatable :: title
        !> 'static', 'modal' or 'dynamic'.
        character(len=:), allocatable :: analysis
        !> 'average_acceleration', 'newmark' or 'central_difference'.
        character(len=:), allocatable :: scheme
        !> Newmark beta in effect (0.25 average acceleration, 0 central difference).
        real(wp) :: beta = 0.25_wp
        !> Newmark gamma in effect (0.5 for average acceleration and central difference).
        real(wp) :: gamma = 0.5_wp
        !> Time step [s] (dynamic; 0 otherwise).
        real(wp) :: h = 0.0_wp
        !> End time [s] (dynamic; 0 otherwise).
        real(wp) :: t_end = 0.0_wp
        !> Number of time steps: whole steps up to the end time, the last one may end slightly
        !> after it (dynamic; 0 otherwise).
        integer(i8) :: n_steps = 0
        !> Number of modes to compute (modal).
        integer :: n_modes = 3
        !> Time steps between stored states.
        integer :: output_interval = 1
        !> Wall-clock seconds between progress lines (0 = none).
        real(wp) :: progress_seconds = 5.0_wp
        !> Time steps between checkpoints (0 = none).
        integer :: checkpoint_interval = 0
        !> Wall-clock seconds between checkpoints (0 = none).
        real(wp) :: checkpoint_seconds = 0.0_wp
        !> Initial displacements (3, n_nodes) [m, rad]; zero unless given in [initial].
        real(wp), allocatable :: u0(:, :)
        !> Initial velocities (3, n_nodes) [m/s, rad/s]; zero unless given in [initial].
        real(wp), allocatable :: v0(:, :)
    contains
        !> What the energy balance of the run's summary line holds beyond the integrator's
        !> error: '' for gamma = 1/2, the scheme's numerical dissipation for gamma > 1/2.
        procedure :: balance_note => run_balance_note
    end type run_config_t

contains

    !> The summary's name of the energy balance: a Newmark scheme with gamma > 1/2 damps the
    !> high frequencies by design (numerical dissipation, of order (gamma - 1/2) h omega^2 per
    !> step and mode), which the audit does not count as a term: the balance is then that
    !> dissipation, negative and growing with the run, besides the integrator's round-off.
    function run_balance_note(self) result(note)
        !> The run's settings.
        class(run_config_t), intent(in) :: self
        !> '', or ' (includes the numerical dissipation of Newmark gamma = ... > 1/2: ...)'.
        character(len=:), allocatable :: note
        note = ''
        if (.not. self%gamma > 0.5_wp) return
        note = ' (includes the numerical dissipation of Newmark gamma = '//to_str(self%gamma)//' > 1/2: negative, '// &
               'not an error)'
    end function run_balance_note

    !> Fill the run and beam configurations from a validated deck, with cross checks.
    subroutine build_config(deck, run, beam, error)
        !> Deck read by io_deck::read_deck with the MULTICOR schema.
        type(deck_t), intent(in) :: deck
        !> Run configuration.
        type(run_config_t), intent(out) :: run
        !> Beam model configuration.
        type(beam_config_t), intent(out) :: beam
        !> Error naming file, line and keyword, if any.
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: fix_line(:, :)
        call build_beam_config(deck, beam, fix_line, error)
        if (allocated(error)) return
        call build_run(deck, beam, run, error)
        if (allocated(error)) return
        call build_initial(deck, beam, fix_line, run%u0, run%v0, error)
    end subroutine build_config

    !> Run configuration and time functions of a deck of particles (no [beam]): the run
    !> settings of a time integration (particles have no static or modal analysis), for a frame
    !> without nodes.
    subroutine build_particles_config(deck, run, functions, error)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> Run configuration.
        type(run_config_t), intent(out) :: run
        !> The deck's time functions.
        type(time_function_slot_t), allocatable, intent(out) :: functions(:)
        !> Error, if any.
        type(error_t), allocatable, intent(out) :: error
        type(beam_config_t) :: frame
        integer, allocatable :: function_ids(:), fix_line(:, :)
        allocate (frame%x(0), frame%y(0), frame%node_id(0), frame%conn(2, 0), frame%elem_section(0))
        allocate (frame%sections(0), frame%loads(0), frame%fixed(3, 0), frame%functions(0), fix_line(3, 0))
        allocate (consistent_mass_t :: frame%mass_scheme)
        if (deck%get_word('run', 'analysis') /= 'dynamic') then
            call make_input_error(error, deck%file, deck%line('run', 'analysis'), 'analysis', &
                                  'particles are integrated in time: set analysis = dynamic (a '// &
                                  deck%get_word('run', 'analysis')//' analysis needs a [beam] model)')
            return
        end if
        call build_time_functions(deck, functions, function_ids, error)
        if (allocated(error)) return
        call build_run(deck, frame, run, error)
        if (allocated(error)) return
        call build_initial(deck, frame, fix_line, run%u0, run%v0, error)
    end subroutine build_particles_config

    !> Run settings: analysis, time integration, modes, output.
    subroutine build_run(deck, beam, run, error)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> Beam configuration (for the number of free DOFs).
        type(beam_config_t), intent(in) :: beam
        !> Run configuration.
        type(run_config_t), intent(inout) :: run
        !> Error, if any.
        type(error_t), allocatable, intent(out) :: error
        call build_run_settings(deck, count(.not. beam%fixed), beam%mass_scheme, 'beam', run, error)
    end subroutine build_run

    !> Run settings ([run], [time], [modal], [output]) of a model with n_free free DOFs whose
    !> mass matrix is assembled under `mass` (`section` names where the mass is chosen, for
    !> messages).
    subroutine build_run_settings(deck, n_free, mass, section, run, error)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> Number of free DOFs of the model.
        integer, intent(in) :: n_free
        !> The model's mass scheme (the central-difference scheme needs a diagonal mass).
        class(mass_scheme_t), intent(in) :: mass
        !> Section choosing the mass matrix ('beam', 'continuum').
        character(len=*), intent(in) :: section
        !> Run configuration.
        type(run_config_t), intent(inout) :: run
        !> Error, if any.
        type(error_t), allocatable, intent(out) :: error
        run%title = deck%get_text('run', 'title')
        run%analysis = deck%get_word('run', 'analysis')
        run%scheme = deck%get_word('time', 'scheme')
        select case (run%scheme)
        case ('newmark')
            run%beta = deck%get_real('time', 'beta')
            run%gamma = deck%get_real('time', 'gamma')
        case ('central_difference')
            run%beta = 0.0_wp
            run%gamma = 0.5_wp
        case default
            run%beta = 0.25_wp
            run%gamma = 0.5_wp
        end select
        if (run%analysis == 'dynamic' .and. run%scheme == 'central_difference' .and. &
            .not. mass%is_diagonal()) then
            call make_input_error(error, deck%file, deck%line('time', 'scheme'), 'scheme', &
                                  'the central-difference scheme needs a lumped mass matrix: set ['//section// &
                                  '] mass = lumped, or use scheme = average_acceleration')
            return
        end if
        run%h = deck%get_real('time', 'step')
        run%t_end = deck%get_real('time', 'end')
        if (run%analysis == 'dynamic' .and. run%h > run%t_end) then
            call make_input_error(error, deck%file, deck%line('time', 'step'), 'step', &
                                  'time step '// &
                                  deck%get_word('time', 'step')//' is larger than the end time '// &
                                  deck%get_word('time', 'end'))
            return
        end if
        if (run%analysis == 'dynamic') then
            call count_steps(error)
            if (allocated(error)) return
            call check_damping(error)
            if (allocated(error)) return
        end if
        run%n_modes = deck%get_int('modal', 'modes')
        if (run%analysis == 'modal' .and. run%n_modes > n_free) then
            call make_input_error(error, deck%file, deck%line('modal', 'modes'), 'modes', &
                                  to_str(run%n_modes)//' modes asked but the model has only '// &
                                  to_str(n_free)//' free DOFs')
            return
        end if
        run%output_interval = deck%get_int('output', 'interval')
        run%progress_seconds = deck%get_real('output', 'progress')
        run%checkpoint_interval = deck%get_int('output', 'checkpoint_interval')
        run%checkpoint_seconds = deck%get_real('output', 'checkpoint_seconds')

    contains

        !> Number of steps end/step, computed in floating point first so that no integer
        !> overflows; refused beyond max_steps.
        subroutine count_steps(error)
            type(error_t), allocatable, intent(out) :: error
            real(wp) :: steps
            steps = steps_to_end(run%t_end, run%h)
            if (steps > real(max_steps, wp)) then
                call make_input_error(error, deck%file, deck%line('time', 'end'), 'end', &
                                      'end time '//deck%get_word('time', 'end')//' with step '// &
                                      deck%get_word('time', 'step')//' needs '//to_str(steps)// &
                                      ' time steps, more than a run can count ('//to_str(max_steps)// &
                                      '): lower the end time or raise the step')
                return
            end if
            run%n_steps = max(ceiling(steps, i8), 1_i8)
        end subroutine count_steps

        !> Refuse Rayleigh damping beyond double precision over one step (a0 h or a1 / h above
        !> 1/epsilon): the inertia and stiffness terms of the step's matrix are then lost in
        !> round-off, and the motion and the energy audit with them.
        subroutine check_damping(error)
            type(error_t), allocatable, intent(out) :: error
            real(wp) :: a0, a1, limit
            a0 = deck%get_real(section, 'rayleigh', 'a0')
            a1 = deck%get_real(section, 'rayleigh', 'a1')
            limit = 1.0_wp/epsilon(1.0_wp)
            if (a0*run%h > limit .or. a1/run%h > limit) then
                call make_input_error(error, deck%file, deck%line(section, 'rayleigh'), 'rayleigh', &
                                      'Rayleigh damping a0 = '//to_str(a0)//' 1/s, a1 = '//to_str(a1)// &
                                      ' s damps more in one step (a0 h = '//to_str(a0*run%h)//', a1/h = '// &
                                      to_str(a1/run%h)//') than double precision can hold next to the '// &
                                      'inertia and stiffness (1/epsilon = '//to_str(limit)//'): check the '// &
                                      'values (a0 in 1/s, a1 in s)')
            end if
        end subroutine check_damping

    end subroutine build_run_settings

    !> Number of time steps of length h up to the end time, as a real (no integer can
    !> overflow; compare with max_steps before converting): whole steps, the last one may end
    !> slightly after t_end.
    pure real(wp) function steps_to_end(t_end, h) result(steps)
        !> End time [s].
        real(wp), intent(in) :: t_end
        !> Time step [s].
        real(wp), intent(in) :: h
        real(wp) :: x
        x = t_end/h*(1.0_wp - relative_roundoff)
        steps = aint(x)
        if (steps < x) steps = steps + 1.0_wp
    end function steps_to_end

end module driver_config
