!> Static analysis of a 2D continuum: K_ff u_f = f_f - K_fp u_p at t = 0 (CHOLMOD), the
!> displacements, the element-centre stresses and the strain energy.
module driver_simulation_continuum_static
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use core_kinds, only: wp
    use core_error, only: error_t, make_error, make_input_error
    use io_deck, only: deck_t
    use fem_dynamic_operator, only: spd_factor_t
    use driver_results, only: results_writer_t
    use driver_checkpoint, only: checkpoint_run_t
    use driver_results_continuum, only: continuum_writer_t
    use driver_simulation, only: report_iface
    use driver_simulation_continuum, only: continuum_simulation_t, continuum_setup
    implicit none
    private
    public :: continuum_static_t

    !> A static continuum run.
    type, extends(continuum_simulation_t) :: continuum_static_t
        !> Factor of K_ff.
        class(spd_factor_t), allocatable :: k_factor
    contains
        !> See `simulation_t%init`: the supports must stop every rigid motion; K_ff is factored.
        procedure :: init => static_init
        !> See `simulation_t%run`.
        procedure :: run => static_run
    end type continuum_static_t

contains

    !> The continuum from the deck, then the factor of K_ff (refused when the supports leave a
    !> rigid motion free).
    subroutine static_init(self, deck, report, error)
        !> The simulation.
        class(continuum_static_t), intent(inout) :: self
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> Where warnings go.
        procedure(report_iface) :: report
        !> Set on any input error.
        type(error_t), allocatable, intent(out) :: error
        integer :: line
        call continuum_setup(self, deck, error)
        if (allocated(error)) return
        if (self%model%stops_rigid_motions()) call self%ops%factor_combination(0.0_wp, 1.0_wp, self%k_factor, error)
        if (allocated(error) .or. .not. self%model%stops_rigid_motions()) then
            line = deck%line('continuum', 'fix')
            if (line == 0) line = deck%line('continuum', 'mesh')
            call make_input_error(error, deck%file, line, 'fix', 'the supports (fix, displacement) do not '// &
                                  'stop every rigid motion (two translations and the rotation): the stiffness '// &
                                  'on the free dofs is singular')
        end if
    end subroutine static_init

    !> The mesh, then the static solution; results into `out` (driver_run adds the XDMF file).
    subroutine static_run(self, out, quiet, report, ck, error)
        !> The simulation.
        class(continuum_static_t), intent(inout) :: self
        !> The results file.
        type(results_writer_t), intent(inout) :: out
        !> No progress lines (a static solve prints none).
        logical, intent(in) :: quiet
        !> Where the summary lines go.
        procedure(report_iface) :: report
        !> Checkpoints (none in a static analysis).
        type(checkpoint_run_t), intent(inout) :: ck
        !> Set on a run or write failure.
        type(error_t), allocatable, intent(out) :: error
        type(continuum_writer_t) :: writer
        call writer%begin(out%file, self%model%mesh, self%settings%analysis, error)
        if (allocated(error)) return
        call run_static(error)

    contains

        !> K_ff u_f = f_f - K_fp u_p.
        subroutine run_static(error)
            type(error_t), allocatable, intent(out) :: error
            real(wp), allocatable :: uf(:), u(:), stress(:, :)
            character(len=160) :: buf
            real(wp) :: energy
            ! Loads at t = 0 (their time functions' values there, as for the beam).
            allocate (uf(self%ops%n_free))
            call self%ops%static_force(0.0_wp, uf)
            call self%k_factor%solve(uf, error)
            if (allocated(error)) return
            u = self%model%expand(uf)
            call self%model%centre_stresses(u, stress, error)
            if (allocated(error)) return
            if (.not. (all(ieee_is_finite(u)) .and. all(ieee_is_finite(stress)))) then
                call make_error(error, 'static solution of the continuum: a displacement or a stress is not '// &
                                'finite; likely cause: loads or moduli far too large or too small')
                return
            end if
            energy = self%ops%total_strain_energy(u)
            if (.not. ieee_is_finite(energy)) then
                call make_error(error, 'static solution of the continuum: the strain energy is not finite; likely '// &
                                'cause: loads or moduli far too large or too small')
                return
            end if
            call writer%write_static(out%file, reshape(u, [2, size(u)/2]), stress, energy, error)
            if (allocated(error)) return
            write (buf, '(a,es13.5e3,a,es13.5e3,a)') 'static solution: max |displacement| = ', maxval(abs(u)), &
                ' m, strain energy = ', energy, ' J'
            call report(trim(buf))
        end subroutine run_static
    end subroutine static_run
end module driver_simulation_continuum_static
