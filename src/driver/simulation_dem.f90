!> Particle (Contact Dynamics) runs: a [particles] deck without [beam].
module driver_simulation_dem
    use core_kinds, only: wp
    use core_error, only: error_t, make_input_error
    use core_strings, only: counted, to_str
    use io_deck, only: deck_t
    use fem_beam_config, only: beam_config_t
    use dem_detection, only: coordinate_limit
    use driver_config, only: run_config_t, build_config
    use driver_config_dem, only: dem_config_t, build_dem_config
    use driver_run_dem, only: run_dem
    use driver_results, only: results_writer_t
    use driver_checkpoint, only: checkpoint_run_t
    use driver_simulation, only: simulation_t, report_iface
    implicit none
    private
    public :: dem_simulation_t, check_dem_coordinates

    !> A run of rigid disks and walls.
    type, extends(simulation_t) :: dem_simulation_t
        !> Empty frame holding the time functions.
        type(beam_config_t) :: beam
        !> Particles, walls, contact laws and solver settings.
        type(dem_config_t) :: dem
    contains
        !> See `simulation_t%init`.
        procedure :: init => dem_init
        !> See `simulation_t%describe`.
        procedure :: describe => dem_describe
        !> See `simulation_t%run`.
        procedure :: run => dem_run
        !> See `simulation_t%checkpoint_kind`.
        procedure :: checkpoint_kind => dem_checkpoint_kind
    end type dem_simulation_t

contains

    !> Configuration of the particles and walls; everything that can fail because of the input.
    subroutine dem_init(self, deck, report, error)
        !> The simulation.
        class(dem_simulation_t), intent(inout) :: self
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> Where warnings go.
        procedure(report_iface) :: report
        !> Set on any input error.
        type(error_t), allocatable, intent(out) :: error
        integer :: i
        call build_config(deck, self%settings, self%beam, error)
        if (allocated(error)) return
        call build_dem_config(deck, self%settings, self%beam%functions, self%dem, error)
        if (allocated(error)) return
        call check_dem_coordinates(deck, self%dem, error)
        if (allocated(error)) return
        do i = 1, size(self%dem%warnings)
            call report(self%dem%warnings(i)%s)
        end do
    end subroutine dem_init

    !> 'dynamic analysis, 40 disks, 2 walls'.
    function dem_describe(self) result(text)
        !> The simulation.
        class(dem_simulation_t), intent(in) :: self
        !> Summary.
        character(len=:), allocatable :: text
        text = self%settings%analysis//' analysis, '//counted(self%dem%system%particles%n, 'disk')//', '// &
               counted(self%dem%system%walls%n, 'wall')
    end function dem_describe

    !> Integrate the particles; results into `out`.
    subroutine dem_run(self, out, quiet, report, ck, error)
        !> The simulation.
        class(dem_simulation_t), intent(inout) :: self
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
        call run_dem(self%settings, self%dem, out, quiet, report, ck, error)
    end subroutine dem_run

    !> Disks and walls must lie in the box the contact detection can represent.
    subroutine check_dem_coordinates(deck, dem, error)
        !> The deck (for messages).
        type(deck_t), intent(in) :: deck
        !> The particle configuration.
        type(dem_config_t), intent(in) :: dem
        !> Set when a disk or a wall end lies beyond the box.
        type(error_t), allocatable, intent(out) :: error
        real(wp) :: limit
        integer :: k
        associate (p => dem%system%particles, w => dem%system%walls)
            if (p%n == 0) return
            limit = coordinate_limit(minval(p%radius(1:p%n)))
            do k = 1, p%n
                if (max(abs(p%x(k)), abs(p%y(k))) <= limit) cycle
                call make_input_error(error, deck%file, dem%disk_line(k), '', 'disk '// &
                                      to_str(k)//' at ('//num(p%x(k))//', '//num(p%y(k))// &
                                      ') m lies beyond the box the run can represent: |x|, |y| <= '// &
                                      num(limit)//' m (4.5e9 times the smallest radius, at most '// &
                                      '1e100 m; coordinates are then known to 1e-6 of the radius)')
                return
            end do
            do k = 1, w%n
                if (max(abs(w%x1(k)), abs(w%y1(k)), abs(w%x2(k)), abs(w%y2(k))) <= limit) cycle
                call make_input_error(error, deck%file, dem%wall_line(k), 'wall', 'wall '// &
                                      to_str(k)//' has an end beyond the box the run can represent: '// &
                                      '|x|, |y| <= '//num(limit)//' m (4.5e9 times the smallest '// &
                                      'disk radius, at most 1e100 m): shorten it')
                return
            end do
        end associate
    end subroutine check_dem_coordinates

    !> A real with 3 significant digits.
    function num(x) result(text)
        real(wp), intent(in) :: x
        character(len=:), allocatable :: text
        character(len=24) :: buf
        write (buf, '(es11.3e3)') x
        text = trim(adjustl(buf))
    end function num

    !> 'particles'.
    function dem_checkpoint_kind(self) result(kind)
        !> The simulation.
        class(dem_simulation_t), intent(in) :: self
        !> Kind of run of its checkpoints.
        character(len=:), allocatable :: kind
        kind = 'particles'
    end function dem_checkpoint_kind
end module driver_simulation_dem
