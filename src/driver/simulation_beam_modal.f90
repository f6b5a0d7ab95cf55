!> Modal analysis of a frame: the lowest circular frequencies and their mass-normalised mode
!> shapes, each named axial or bending by its share of axial strain energy.
module driver_simulation_beam_modal
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use core_kinds, only: wp
    use core_constants, only: two_pi
    use core_error, only: error_t, make_error, make_input_error
    use io_deck, only: deck_t
    use fem_beam_model, only: beam_model_t
    use fem_modal, only: solve_modal, axial_fractions, mode_kind, dominant_fraction
    use driver_config, only: run_config_t
    use driver_results, only: results_writer_t
    use driver_checkpoint, only: checkpoint_run_t
    use driver_simulation, only: report_iface
    use driver_simulation_beam, only: beam_simulation_t, beam_setup
    implicit none
    private
    public :: beam_modal_t

    !> A modal frame run.
    type, extends(beam_simulation_t) :: beam_modal_t
        !> Circular frequencies [rad/s] (solved by `init`: its failures are input errors).
        real(wp), allocatable :: omega(:)
        !> Mass-normalised mode shapes on the free DOFs (n_free, n_modes).
        real(wp), allocatable :: shapes(:, :)
    contains
        !> See `simulation_t%init`: the modes are solved here.
        procedure :: init => modal_init
        !> See `simulation_t%run`.
        procedure :: run => modal_run
    end type beam_modal_t

contains

    !> Settings and model, then the modes (a failure blames the sections).
    subroutine modal_init(self, deck, report, error)
        !> The simulation.
        class(beam_modal_t), intent(inout) :: self
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> Where warnings go (none for beams).
        procedure(report_iface) :: report
        !> Set on any input error.
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: message
        call beam_setup(self, deck, error)
        if (allocated(error)) return
        call solve_modal(self%model, self%settings%n_modes, self%omega, self%shapes, error)
        if (.not. allocated(error)) then
            if (.not. (all(ieee_is_finite(self%omega)) .and. all(ieee_is_finite(self%shapes)))) &
                call make_error(error, 'modal analysis: a frequency or a mode shape is not finite; '// &
                                'likely cause: a stiffness, density or section far too large or too small')
        end if
        if (allocated(error)) then
            message = error%message
            call make_input_error(error, deck%file, deck%line('beam', 'section'), 'section', message)
        end if
    end subroutine modal_init

    !> The mesh, then the modes and their kinds.
    subroutine modal_run(self, out, quiet, report, ck, error)
        !> The simulation.
        class(beam_modal_t), intent(inout) :: self
        !> The results file.
        type(results_writer_t), intent(inout) :: out
        !> No progress lines (a modal analysis prints none).
        logical, intent(in) :: quiet
        !> Where the mode lines go.
        procedure(report_iface) :: report
        !> Checkpoints (none in a modal analysis).
        type(checkpoint_run_t), intent(inout) :: ck
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        call self%write_mesh(out, error)
        if (allocated(error)) return
        call run_modal(self%settings, self%model, self%omega, self%shapes, out, report, error)
    end subroutine modal_run

    subroutine run_modal(run, model, omega, shapes, out, report, error)
        type(run_config_t), intent(in) :: run
        type(beam_model_t), intent(in) :: model
        real(wp), intent(in) :: omega(:)
        real(wp), contiguous, intent(in) :: shapes(:, :)
        type(results_writer_t), intent(inout) :: out
        procedure(report_iface) :: report
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: full(:, :, :), fraction(:)
        character(len=160) :: buf
        character(len=:), allocatable :: kinds
        character(len=5) :: share
        integer :: k
        allocate (full(3, model%n_nodes, run%n_modes))
        call axial_fractions(model, shapes, fraction, error)
        if (allocated(error)) return
        kinds = ''
        do k = 1, run%n_modes
            call model%expand(shapes(:, k), full(:, :, k))
            kinds = trim(kinds//' '//mode_kind(fraction(k)))
            write (buf, '(a,i3,a,es15.7e3,a,es15.7e3,a)') 'mode ', k, ': omega = ', omega(k), &
                ' rad/s, f = ', omega(k)/two_pi, ' Hz, '//mode_kind(fraction(k))
            if (fraction(k) >= 0) then
                write (share, '(f5.1)') 100*fraction(k)
                buf = trim(buf)//' (axial strain energy '//trim(adjustl(share))//' %)'
            end if
            call report(trim(buf))
        end do
        call out%beam%write_modal(out%file, omega, full, error)
        if (allocated(error)) return
        call out%beam%write_modal_kinds(out%file, fraction, adjustl(kinds), dominant_fraction, error)
    end subroutine run_modal
end module driver_simulation_beam_modal
