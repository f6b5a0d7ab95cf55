!> Static analysis of a 2D continuum: K_ff u_f = f_f - K_fp u_p at t = 0 (CHOLMOD), the
!> displacements, the element-centre stresses, the support reactions and the strain energy.
module driver_simulation_continuum_static
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use core_kinds, only: wp
    use core_error, only: error_t, make_error, make_input_error
    use core_strings, only: to_str
    use io_deck, only: deck_t
    use fem_dynamic_operator, only: spd_factor_t
    use driver_results, only: results_writer_t
    use driver_checkpoint, only: checkpoint_run_t
    use driver_results_continuum, only: continuum_writer_t
    use driver_simulation, only: report_iface
    use driver_simulation_continuum, only: continuum_simulation_t, continuum_setup
    use driver_displacement_scale, only: largest_displacement, model_extent, large_displacement_warning
    implicit none
    private
    public :: continuum_static_t

    !> A static continuum run.
    type, extends(continuum_simulation_t) :: continuum_static_t
        !> Factor of K_ff.
        class(spd_factor_t), allocatable :: k_factor
        !> The solution on the free dofs (m), K_ff u_f = f_f - K_fp u_p, solved by `init`.
        real(wp), allocatable :: uf(:)
    contains
        !> See `simulation_t%init`: the supports must stop every rigid motion of every body;
        !> K_ff is factored and the system solved (--check refuses a solution out of equilibrium).
        procedure :: init => static_init
        !> See `simulation_t%run`.
        procedure :: run => static_run
    end type continuum_static_t

contains

    !> The continuum from the deck, then the factor of K_ff and the solution (refused when the
    !> supports leave a rigid motion of a body free, or the solution is out of equilibrium).
    subroutine static_init(self, deck, report, error)
        !> The simulation.
        class(continuum_static_t), intent(inout) :: self
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> Where warnings go.
        procedure(report_iface) :: report
        !> Set on any input error.
        type(error_t), allocatable, intent(out) :: error
        integer :: line, unheld, n_bodies, e
        integer, allocatable :: body(:)
        real(wp), allocatable :: xb(:, :)
        character(len=:), allocatable :: where_, kw
        call continuum_setup(self, deck, error)
        if (allocated(error)) return
        ! the keyword named: the first fix, or the first displacement when there is no fix
        kw = 'fix'
        line = deck%line('continuum', 'fix')
        if (line == 0) then
            kw = 'displacement'
            line = deck%line('continuum', 'displacement')
        end if
        ! Supports are checked per body (connected part of the mesh): a body held by nothing
        ! leaves K_ff singular whatever holds the others, and the factorisation does not
        ! always notice (a round-off pivot may come out positive: displacements of 1e11 m).
        call self%model%mesh%bodies(body, n_bodies)
        unheld = self%model%unheld_body(body)
        if (unheld > 0 .and. line == 0) then
            call make_input_error(error, deck%file, deck%header_line('continuum'), '', '[continuum] has no '// &
                                  'support (no fix or displacement record): a static analysis needs supports '// &
                                  'that stop the rigid motions (two translations and the rotation) of every body, '// &
                                  'e.g. fix = <node set> x y on a clamped edge')
            return
        end if
        if (line == 0) line = deck%line('continuum', 'mesh')
        if (unheld > 0 .and. n_bodies == 1) then
            call make_input_error(error, deck%file, line, kw, 'the supports (fix, displacement) do not '// &
                                  'stop every rigid motion (two translations and the rotation): the stiffness '// &
                                  'on the free dofs is singular')
            return
        else if (unheld > 0) then
            xb = pack_body(self%model%mesh%x, body == unheld)
            e = findloc(body(self%model%mesh%connectivity(1, :)), unheld, dim=1)
            where_ = ''
            if (e > 0) where_ = ' with '//self%model%mesh%element_label(e)
            call make_input_error(error, deck%file, line, kw, 'the supports (fix, displacement) do not '// &
                                  'stop every rigid motion (two translations and the rotation) of body '// &
                                  to_str(unheld)//' of the mesh''s '//to_str(n_bodies)//' (parts that share no node), '// &
                                  'the one spanning ['//to_str(minval(xb(1, :)))//', '//to_str(maxval(xb(1, :)))// &
                                  '] x ['//to_str(minval(xb(2, :)))//', '//to_str(maxval(xb(2, :)))//'] m'// &
                                  where_//': the stiffness on the free dofs is singular; '// &
                                  'each body needs supports of its own (a static analysis has no contact between '// &
                                  'bodies)')
            return
        end if
        call self%ops%factor_combination(0.0_wp, 1.0_wp, self%k_factor, error)
        if (allocated(error)) then
            if (index(error%message, 'not positive definite') == 0) return
            ! Every body is held: a part joined to the rest of its body by one node turns
            ! about it freely (a hinge), or the stiffnesses span more than double precision.
            call make_input_error(error, deck%file, line, kw, 'the supports (fix, displacement) do not '// &
                                  'stop every rigid motion: the stiffness on the free dofs is not positive '// &
                                  'definite although the supports hold every body; likely cause: a part joined '// &
                                  'to the rest of its body by a single node turns freely about it (a hinge), '// &
                                  'or the moduli of the materials differ by too many orders of magnitude')
            return
        end if
        call solve(error)

    contains

        !> K_ff u_f = f_f - K_fp u_p at t = 0, and its equilibrium checked.
        !> A static analysis takes the time functions at t = 0: when the deck loads the body
        !> (load, traction, gravity, displacement) and all of it is zero there (a ramp, a step
        !> that starts later), the solution is zero, which the deck hardly means.
        subroutine warn_loads_zero_at_start(f)
            !> Right-hand side on the free dofs at t = 0.
            real(wp), intent(in) :: f(:)
            integer :: first, k
            character(len=*), parameter :: keys(4) = [character(len=12) :: 'load', 'traction', 'gravity', &
                                                                                                                     'displacement']
            if (any(f /= 0.0_wp)) return
            first = 0
            do k = 1, size(keys)
                associate (line => deck%line('continuum', trim(keys(k))))
                    if (line > 0 .and. (first == 0 .or. line < first)) first = line
                end associate
            end do
            if (first == 0) return
            call report('warning: '//deck%file//':'//to_str(first)//': every load and prescribed displacement '// &
                        'of this static analysis is zero at t = 0, where it takes the values of their time '// &
                        'functions ([functions]): the solution is zero')
        end subroutine warn_loads_zero_at_start

        subroutine solve(error)
            type(error_t), allocatable, intent(out) :: error
            real(wp), allocatable :: f(:), ku(:)
            real(wp) :: residual
            character(len=16) :: buf
            !> Largest |K u - f| / |f| of an accepted solution.
            real(wp), parameter :: max_residual = 1.0e-3_wp
            ! Loads at t = 0 (their time functions' values there, as for the beam).
            allocate (self%uf(self%ops%n_free), f(self%ops%n_free), ku(self%ops%n_free))
            call self%ops%static_force(0.0_wp, f)
            call warn_loads_zero_at_start(f)
            self%uf = f
            call self%k_factor%solve(self%uf, error)
            if (allocated(error)) return
            ! Equilibrium of the solution: the supports' rank test cannot see a part turning
            ! about a single node (a hinge), nor stiffnesses spanning more than double
            ! precision; the factorisation then meets a pivot of round-off size, which may come
            ! out positive, and the solve returns displacements of 1e12 m that satisfy
            ! K u = f nowhere (|K u - f| of the order of |f|, and a strain energy of any sign).
            ! Written with exit 0 they would pass for results: refused instead, here so that
            ! --check sees it too (the solve costs little beside the factorisation). The bound is
            ! max_residual: the solution is then the exact one for loads within 0.1 % of the
            ! given ones. A sound solve stays far below it: 1e-16 to 3e-10 on the example
            ! decks, 6e-5 on a cantilever 1000 times longer than deep; a hinge gives 4.5.
            ! The sign of the energy is no test: a prescribed rigid motion has an energy of
            ! round-off size and either sign.
            call self%ops%stiffness_times(self%uf, ku)
            residual = norm2(ku - f)
            if (residual > max_residual*norm2(f)) then
                write (buf, '(es9.2e3)') residual/norm2(f)
                call make_input_error(error, deck%file, line, 'fix', 'the static solution does not satisfy '// &
                                      'equilibrium (|K u - f| = '//trim(adjustl(buf))//' |f|, above 1e-3): the '// &
                                      'stiffness on the free dofs is singular or too ill-conditioned for double '// &
                                      'precision; likely cause: a part joined to the rest of its body by a single '// &
                                      'node turns freely about it (a hinge the supports do not hold), or moduli or '// &
                                      'element sizes that span too many orders of magnitude')
            end if
        end subroutine solve

        !> Coordinates of the nodes of a body.
        pure function pack_body(x, in) result(xb)
            real(wp), intent(in) :: x(:, :)
            logical, intent(in) :: in(:)
            real(wp), allocatable :: xb(:, :)
            xb = reshape([pack(x(1, :), in), pack(x(2, :), in)], [count(in), 2], order=[1, 2])
            xb = transpose(xb)
        end function pack_body
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
        call writer%begin(out%file, self%model, error)
        if (allocated(error)) return
        call run_static(error)

    contains

        !> Stresses, reactions and energy of the solution, written.
        subroutine run_static(error)
            type(error_t), allocatable, intent(out) :: error
            real(wp), allocatable :: u(:), stress(:, :), szz(:), vm(:), r(:), rest(:)
            character(len=160) :: buf
            character(len=:), allocatable :: warning
            real(wp) :: energy, u_max
            u = self%model%expand(self%uf)
            call self%model%centre_stresses(u, stress, error)
            if (allocated(error)) return
            call self%model%stress_measures(stress, szz, vm)
            ! (von Mises squares the stresses: it is not finite beyond 1e154 Pa)
            if (.not. (all(ieee_is_finite(u)) .and. all(ieee_is_finite(stress)) .and. all(ieee_is_finite(vm)))) then
                call make_error(error, 'static solution of the continuum: a displacement or a stress is not '// &
                                'finite; likely cause: loads or moduli far too large or too small')
                return
            end if
            ! Reactions r = K u - f(0) on the prescribed dofs (the forces the supports apply to
            ! the body, as /continuum/energy/reaction of a dynamic run); on the free dofs K u - f
            ! is the solve's residual, not a force of the supports: 0 there.
            allocate (rest(size(u)), source=0.0_wp)
            r = self%ops%reactions(0.0_wp, u, rest, rest)
            r = merge(r, 0.0_wp, self%model%prescribed)
            energy = self%ops%total_strain_energy(u)
            if (.not. (ieee_is_finite(energy) .and. all(ieee_is_finite(r)))) then
                call make_error(error, 'static solution of the continuum: the strain energy or a reaction is not '// &
                                'finite; likely '// &
                                'cause: loads or moduli far too large or too small')
                return
            end if
            call writer%write_static(out%file, reshape(u, [2, size(u)/2]), stress, szz, vm, &
                                     reshape(r, [2, size(r)/2]), energy, error)
            if (allocated(error)) return
            ! The largest nodal displacement sqrt(ux^2 + uy^2), the measure the warning below uses.
            u_max = largest_displacement(reshape(u, [2, size(u)/2]))
            write (buf, '(a,es13.5e3,a,es13.5e3,a)') 'static solution: max |displacement| = ', u_max, &
                ' m, strain energy = ', energy, ' J'
            call report(trim(buf))
            associate (x => self%model%mesh%x)
                warning = large_displacement_warning(u_max, model_extent(x(1, :), x(2, :)), &
                                                     '[continuum] material, load, traction, gravity, '// &
                                                     'displacement, mesh')
            end associate
            if (len(warning) > 0) call report(warning)
        end subroutine run_static
    end subroutine static_run
end module driver_simulation_continuum_static
