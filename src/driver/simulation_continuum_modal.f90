!> Modal analysis of a 2D continuum: the lowest circular frequencies and their mode shapes
!> (band LAPACK on the reduced K and M).
module driver_simulation_continuum_modal
    use core_kinds, only: wp
    use core_constants, only: two_pi
    use core_error, only: error_t
    use io_deck, only: deck_t
    use driver_results, only: results_writer_t
    use driver_checkpoint, only: checkpoint_run_t
    use driver_results_continuum, only: continuum_writer_t
    use driver_simulation, only: report_iface
    use driver_simulation_continuum, only: continuum_simulation_t, continuum_setup, check_density
    implicit none
    private
    public :: continuum_modal_t

    !> A modal continuum run.
    type, extends(continuum_simulation_t) :: continuum_modal_t
    contains
        !> See `simulation_t%init`: every density must be > 0.
        procedure :: init => modal_init
        !> See `simulation_t%run`.
        procedure :: run => modal_run
    end type continuum_modal_t

contains

    !> The continuum from the deck, then its densities.
    subroutine modal_init(self, deck, report, error)
        !> The simulation.
        class(continuum_modal_t), intent(inout) :: self
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> Where warnings go.
        procedure(report_iface) :: report
        !> Set on any input error.
        type(error_t), allocatable, intent(out) :: error
        call continuum_setup(self, deck, error)
        if (allocated(error)) return
        call check_density(deck, error)
    end subroutine modal_init

    !> The mesh, then the modes; results into `out` (driver_run adds the XDMF file).
    subroutine modal_run(self, out, quiet, report, ck, error)
        !> The simulation.
        class(continuum_modal_t), intent(inout) :: self
        !> The results file.
        type(results_writer_t), intent(inout) :: out
        !> No progress lines (a modal analysis prints none).
        logical, intent(in) :: quiet
        !> Where the mode lines go.
        procedure(report_iface) :: report
        !> Checkpoints (none in a modal analysis).
        type(checkpoint_run_t), intent(inout) :: ck
        !> Set on a run or write failure.
        type(error_t), allocatable, intent(out) :: error
        type(continuum_writer_t) :: writer
        call writer%begin(out%file, self%model, error)
        if (allocated(error)) return
        call run_modal(error)

    contains

        !> Lowest modes.
        subroutine run_modal(error)
            type(error_t), allocatable, intent(out) :: error
            real(wp), allocatable :: omega(:), shapes(:, :), full(:, :, :), u(:)
            character(len=120) :: buf
            integer :: k
            call self%ops%solve_modes(self%settings%n_modes, omega, shapes, error)
            if (allocated(error)) return
            allocate (full(2, self%model%mesh%node_count(), size(omega)))
            do k = 1, size(omega)
                ! Mode shapes vanish on the prescribed dofs.
                u = self%model%expand(shapes(:, k)) - self%model%prescribed_at(0.0_wp, 0)
                full(:, :, k) = reshape(u, [2, self%model%mesh%node_count()])
                write (buf, '(a,i3,a,es15.7e3,a,es15.7e3,a)') 'mode ', k, ': omega = ', omega(k), &
                    ' rad/s, f = ', omega(k)/two_pi, ' Hz'
                call report(trim(buf))
            end do
            call writer%write_modal(out%file, omega, full, error)
        end subroutine run_modal
    end subroutine modal_run
end module driver_simulation_continuum_modal
