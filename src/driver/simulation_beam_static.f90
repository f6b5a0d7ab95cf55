!> Static analysis of a frame: K u = F at t = 0, the displacements and the support reactions.
module driver_simulation_beam_static
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use core_kinds, only: wp
    use core_error, only: error_t, make_error, make_input_error
    use core_strings, only: to_str
    use io_deck, only: deck_t
    use fem_beam_model, only: beam_model_t
    use fem_static, only: solve_static
    use driver_results, only: results_writer_t
    use driver_checkpoint, only: checkpoint_run_t
    use driver_simulation, only: report_iface
    use driver_simulation_beam, only: beam_simulation_t, beam_setup
    use driver_displacement_scale, only: largest_displacement, model_extent, large_displacement_warning
    implicit none
    private
    public :: beam_static_t

    !> A static frame run.
    type, extends(beam_simulation_t) :: beam_static_t
    contains
        !> See `simulation_t%init`: the supports must stop every rigid-body motion.
        procedure :: init => static_init
        !> See `simulation_t%run`.
        procedure :: run => static_run
    end type beam_static_t

contains

    !> Settings and model, then the supports.
    subroutine static_init(self, deck, report, error)
        !> The simulation.
        class(beam_static_t), intent(inout) :: self
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> Where warnings go (loads all zero at t = 0).
        procedure(report_iface) :: report
        !> Set on any input error.
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: message
        integer :: line
        call beam_setup(self, deck, error)
        if (allocated(error)) return
        ! A static solve needs supports that stop every rigid-body motion: the error names the
        ! first `fix` of the deck (the supports as a whole; the message names the part), or,
        ! when there is none, the [beam] header with the missing supports as the cause.
        call self%model%check_supports(error)
        if (allocated(error)) then
            message = error%message
            line = deck%line('beam', 'fix')
            if (line == 0) then
                call make_input_error(error, deck%file, deck%header_line('beam'), '', '[beam] has no support (no '// &
                                      'fix record): a static analysis needs fixed DOFs that stop the frame''s '// &
                                      'rigid motions (x, y and rotation), e.g. fix = <node> all at a clamped end')
                return
            end if
            call make_input_error(error, deck%file, line, 'fix', message)
            return
        end if
        call warn_loads_zero_at_start()
    contains
        !> A static analysis takes the loads' time functions at t = 0: when every load given
        !> is zero there (a ramp, a step that starts later), the solution is zero, which the
        !> deck hardly means.
        subroutine warn_loads_zero_at_start()
            real(wp), allocatable :: f(:)
            integer :: first
            first = deck%line('beam', 'load')
            if (deck%line('beam', 'distributed') > 0) then
                if (first == 0) then
                    first = deck%line('beam', 'distributed')
                else
                    first = min(first, deck%line('beam', 'distributed'))
                end if
            end if
            if (first == 0) return
            allocate (f(self%model%n_free))
            call self%model%external_force(0.0_wp, f)
            if (any(f /= 0.0_wp)) return
            call report('warning: '//deck%file//':'//to_str(first)//': every load of this static analysis '// &
                        'is zero at t = 0, where it takes the values of their time functions ([functions]): '// &
                        'the solution is zero')
        end subroutine warn_loads_zero_at_start
    end subroutine static_init

    !> The mesh, then the static solution.
    subroutine static_run(self, out, quiet, report, ck, error)
        !> The simulation.
        class(beam_static_t), intent(inout) :: self
        !> The results file.
        type(results_writer_t), intent(inout) :: out
        !> No progress lines (a static solve prints none).
        logical, intent(in) :: quiet
        !> Where the summary line goes.
        procedure(report_iface) :: report
        !> Checkpoints (none in a static analysis).
        type(checkpoint_run_t), intent(inout) :: ck
        !> Set on a run or write failure.
        type(error_t), allocatable, intent(out) :: error
        call self%write_mesh(out, error)
        if (allocated(error)) return
        call run_static(self%model, out, report, error)
    end subroutine static_run

    subroutine run_static(model, out, report, error)
        type(beam_model_t), intent(in) :: model
        type(results_writer_t), intent(inout) :: out
        procedure(report_iface) :: report
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: u(:), d(:, :), r(:, :)
        real(wp) :: u_max
        character(len=120) :: buf
        character(len=:), allocatable :: warning
        call solve_static(model, 0.0_wp, u, error)
        if (allocated(error)) return
        allocate (d(3, model%n_nodes), r(3, model%n_nodes))
        call model%expand(u, d)
        call model%reactions(u, 0.0_wp, r)
        if (.not. (all(ieee_is_finite(d)) .and. all(ieee_is_finite(r)))) then
            call make_error(error, 'static solution: a displacement or a reaction is not finite; '// &
                            'likely cause: a load or a stiffness far too large or too small (check the '// &
                            'magnitudes in [beam])')
            return
        end if
        call out%beam%write_static(out%file, d, r, error)
        if (allocated(error)) return
        ! The largest nodal displacement sqrt(u^2 + w^2), the measure the warning below uses.
        u_max = largest_displacement(d(1:2, :))
        write (buf, '(a,es13.5e3,a)') 'static solution: max |displacement| = ', u_max, ' m'
        call report(trim(buf))
        warning = large_displacement_warning(u_max, model_extent(model%x, model%y), &
                                             '[beam] section, load, distributed, gravity, line, node')
        if (len(warning) > 0) call report(warning)
    end subroutine run_static
end module driver_simulation_beam_static
