!> Coupled (Arlequin) runs: a deck with [beam], [particles] and [coupling].
module driver_simulation_coupled
    use core_error, only: error_t, make_input_error
    use core_strings, only: to_str
    use io_deck, only: deck_t
    use fem_beam_config, only: beam_config_t
    use driver_config, only: run_config_t, build_config
    use driver_config_dem, only: dem_config_t, build_dem_config
    use driver_config_coupling, only: coupled_setup_t, build_coupling_config
    use driver_run_coupled, only: build_coupled, run_coupled
    use coupling_arlequin, only: coupled_system_t
    use driver_results, only: results_writer_t
    use driver_checkpoint, only: checkpoint_run_t
    use driver_simulation, only: simulation_t, report_iface
    use driver_simulation_dem, only: check_dem_coordinates
    implicit none
    private
    public :: coupled_simulation_t

    !> A beam and particles glued in an overlap.
    type, extends(simulation_t) :: coupled_simulation_t
        !> Frame description.
        type(beam_config_t) :: beam
        !> Particles, walls, contact laws and solver settings.
        type(dem_config_t) :: dem
        !> Coupling description from the deck.
        type(coupled_setup_t) :: coupling
        !> The coupled system.
        type(coupled_system_t), allocatable :: sys
    contains
        !> See `simulation_t%init`.
        procedure :: init => coupled_init
        !> See `simulation_t%describe`.
        procedure :: describe => coupled_describe
        !> See `simulation_t%run`.
        procedure :: run => coupled_run
        !> See `simulation_t%checkpoint_kind`.
        procedure :: checkpoint_kind => coupled_checkpoint_kind
    end type coupled_simulation_t

contains

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
        call check_dem_coordinates(deck, self%dem, error)
        if (allocated(error)) return
        call build_coupling_config(deck, self%settings, self%beam, self%dem, self%coupling, error)
        if (allocated(error)) return
        do i = 1, size(self%coupling%warnings)
            call report(self%coupling%warnings(i)%s)
        end do
        allocate (self%sys)
        call build_coupled(self%settings, self%beam, self%dem, self%coupling, self%sys, error)
        if (allocated(error)) then
            message = error%message
            call make_input_error(error, deck%file, self%coupling%overlap_line, 'overlap', message)
        end if
    end subroutine coupled_init

    !> 'coupled dynamic analysis, 11 beam nodes, 40 disks, 12 coupled'.
    function coupled_describe(self) result(text)
        !> The simulation.
        class(coupled_simulation_t), intent(in) :: self
        !> Summary.
        character(len=:), allocatable :: text
        text = 'coupled '//self%settings%analysis//' analysis, '//to_str(size(self%beam%x))//' beam nodes, '// &
               to_str(self%dem%system%particles%n)//' disks, '//to_str(self%sys%op%n_points)//' coupled'
    end function coupled_describe

    !> The coupled time integration; results into `out`.
    subroutine coupled_run(self, out, quiet, report, ck, error)
        !> The simulation.
        class(coupled_simulation_t), intent(inout) :: self
        !> The results file.
        type(results_writer_t), intent(inout) :: out
        !> No progress lines.
        logical, intent(in) :: quiet
        !> Where progress and summary lines go.
        procedure(report_iface) :: report
        !> Checkpoints (and the one to restart from).
        type(checkpoint_run_t), intent(inout) :: ck
        !> Set on a run or write failure.
        type(error_t), allocatable, intent(out) :: error
        call run_coupled(self%settings, self%beam, self%dem, self%sys, out, quiet, report, ck, error)
    end subroutine coupled_run

    !> 'coupled'.
    function coupled_checkpoint_kind(self) result(kind)
        !> The simulation.
        class(coupled_simulation_t), intent(in) :: self
        !> Kind of run of its checkpoints.
        character(len=:), allocatable :: kind
        kind = 'coupled'
    end function coupled_checkpoint_kind
end module driver_simulation_coupled
