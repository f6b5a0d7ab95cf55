!> Particle (Contact Dynamics) runs: a [particles] deck without [beam].
module driver_simulation_dem
    use core_kinds, only: i8
    use core_error, only: error_t
    use core_strings, only: string_t, counted
    use core_timefunc, only: time_function_slot_t
    use io_deck, only: deck_t
    use driver_config, only: build_particles_config
    use driver_config_dem, only: dem_config_t, build_dem_config
    use driver_run_dem, only: run_dem
    use driver_results, only: results_writer_t
    use driver_checkpoint, only: checkpoint_run_t
    use driver_simulation, only: simulation_t, report_iface
    use driver_run_kind, only: check_beam_keywords_unused
    use driver_swept_bonds, only: swept_bonds_warning
    use driver_model_size, only: size_estimate_t, model_size_t
    implicit none
    private
    public :: dem_simulation_t, add_particles_size

    !> A run of rigid disks and walls.
    type, extends(simulation_t) :: dem_simulation_t
        !> The deck's time functions.
        type(time_function_slot_t), allocatable :: functions(:)
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
        !> See `simulation_t%has_time_loop`: yes.
        procedure :: has_time_loop => dem_has_time_loop
        !> See `simulation_t%check_deck`: no beam settings.
        procedure :: check_deck => dem_check_deck
        !> See `simulation_t%deck_warnings`: bonds swept one contact at a time.
        procedure :: deck_warnings => dem_deck_warnings
        !> See `simulation_t%size_estimate`: the disks (`add_particles_size`).
        procedure :: size_estimate => dem_size_estimate
    end type dem_simulation_t

contains

    !> See `add_particles_size`.
    subroutine dem_size_estimate(self, deck, estimate, error)
        !> The simulation (not yet initialised).
        class(dem_simulation_t), intent(in) :: self
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> The estimate, the disks added.
        type(size_estimate_t), intent(inout) :: estimate
        !> Never set (too many disks to number is refused on the whole estimate,
        !> driver_model_size::check_size_estimate).
        type(error_t), allocatable, intent(out) :: error
        call add_particles_size(deck, estimate)
    end subroutine dem_size_estimate

    !> The particles' part of a memory estimate (a particle run's, a coupled run's): the disks
    !> given one by one and those of each `row`, `deposit`, `square_lattice` and `hex_lattice`
    !> record.
    subroutine add_particles_size(deck, estimate)
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> The estimate, the disks added.
        type(size_estimate_t), intent(inout) :: estimate
        integer :: k
        call estimate%add_count(model_size_t(disks=int(deck%count('particles', 'disk'), i8)))
        do k = 1, size(deck%entries)
            associate (e => deck%entries(k))
                if (e%section /= 'particles') cycle
                select case (e%keyword)
                case ('row', 'deposit')
                    call estimate%add_record(model_size_t(disks=int(e%int('n'), i8)), k, e)
                case ('square_lattice', 'hex_lattice')
                    call estimate%add_record(model_size_t(disks=int(e%int('nx'), i8)*int(e%int('ny'), i8)), k, e)
                end select
            end associate
        end do
    end subroutine add_particles_size

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
        call build_particles_config(deck, self%settings, self%functions, error)
        if (allocated(error)) return
        call build_dem_config(deck, self%settings, self%functions, self%dem, error)
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

    !> 'particles'.
    function dem_checkpoint_kind(self) result(kind)
        !> The simulation.
        class(dem_simulation_t), intent(in) :: self
        !> Kind of run of its checkpoints.
        character(len=:), allocatable :: kind
        kind = 'particles'
    end function dem_checkpoint_kind

    !> True: the Moreau-Jean steps.
    pure logical function dem_has_time_loop(self)
        !> The simulation.
        class(dem_simulation_t), intent(in) :: self
        dem_has_time_loop = .true.
    end function dem_has_time_loop

    !> Error for beam-only keywords in a particle deck.
    subroutine dem_check_deck(self, deck, error)
        !> The simulation.
        class(dem_simulation_t), intent(in) :: self
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> Error naming the first such keyword, if any.
        type(error_t), allocatable, intent(out) :: error
        call check_beam_keywords_unused(deck, error)
    end subroutine dem_check_deck

    !> A warning for bonds swept one contact at a time (`method = nlgs` or `coarse`).
    function dem_deck_warnings(self, deck) result(warnings)
        !> The simulation.
        class(dem_simulation_t), intent(in) :: self
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> Bonds swept one contact at a time (driver_swept_bonds).
        type(string_t), allocatable :: warnings(:)
        character(len=:), allocatable :: message
        allocate (warnings(0))
        message = swept_bonds_warning(deck)
        if (len(message) > 0) warnings = [warnings, string_t(message)]
    end function dem_deck_warnings
end module driver_simulation_dem
