!> Arlequin weight functions alpha(s) along the beam (doc/theory.md section 6.1): constant, linear
!> and cubic ramps over an overlap interval, with a floor.
!>
!> The overlap runs from `s_fe` (the end next to the FE-only zone) to `s_particle` (the end
!> next to the particle-only zone); either may be the larger. With xi = (s - s_fe)/(s_particle
!> - s_fe) the weight is
!> - alpha = 1 for xi < 0 (FE only), alpha = 0 for xi > 1 (particles only);
!> - inside the closed overlap 0 <= xi <= 1: alpha = clip(r(xi), alpha_min, 1 - alpha_min),
!>   the ends widened by relative_roundoff times the larger end's abscissa (a disk centred on
!>   an end has an abscissa rounded to either side of it: it is coupled either way),
!>   with the ramp r(xi) = c (constant), 1 - xi (linear) or 1 - (3 xi^2 - 2 xi^3) (cubic,
!>   zero slope at both ends).
!> The floor keeps every coupled point (placed inside the overlap) away from 0 and 1, where
!> one side's mass vanishes and the multiplier system becomes singular.
!>
!> The three shapes are cubic polynomials r(xi) = c0 + c1 xi + c2 xi^2 + c3 xi^3, so one
!> concrete type covers them; alpha is then a piecewise cubic between its breakpoints (the
!> overlap ends and the points where the floor starts to act), which the FE assembly
!> integrates exactly.
module coupling_weights
    use core_kinds, only: wp
    use core_error, only: error_t, make_error
    use core_sort, only: sort_in_place
    use core_weight, only: weight_function_t
    use core_constants, only: relative_roundoff
    implicit none
    private
    public :: weight_config_t, overlap_weight_t, make_weight

    !> Description of a weight, as read from the deck.
    type :: weight_config_t
        !> Shape of the ramp: 'constant', 'linear' or 'cubic'.
        character(len=16) :: shape = 'cubic'
        !> Abscissa of the overlap end next to the FE-only zone [m].
        real(wp) :: s_fe = 0.0_wp
        !> Abscissa of the overlap end next to the particle-only zone [m].
        real(wp) :: s_particle = 0.0_wp
        !> Floor: alpha stays in [alpha_min, 1 - alpha_min] inside the overlap, 0 < alpha_min < 1/2.
        real(wp) :: alpha_min = 1.0e-3_wp
        !> Value of the constant weight inside the overlap (shape 'constant' only).
        real(wp) :: constant = 0.5_wp
    end type weight_config_t

    !> Weight over an overlap interval: 1 before it, 0 after it, the clipped cubic ramp
    !> r(xi) inside (see the module description). Build it with `make_weight`.
    type, extends(weight_function_t) :: overlap_weight_t
        !> Shape name ('constant', 'linear' or 'cubic'), for messages and output.
        character(len=16) :: shape = 'cubic'
        !> Abscissa of the overlap end next to the FE-only zone [m].
        real(wp) :: s_fe = 0.0_wp
        !> Abscissa of the overlap end next to the particle-only zone [m].
        real(wp) :: s_particle = 1.0_wp
        !> Floor of the weight inside the overlap.
        real(wp) :: alpha_min = 1.0e-3_wp
        !> Coefficients c0..c3 of the ramp r(xi) = sum c_k xi^k.
        real(wp) :: coef(0:3) = [1.0_wp, 0.0_wp, -3.0_wp, 2.0_wp]
    contains
        !> alpha(s), see the module description.
        procedure :: value => overlap_value
        !> Overlap ends and the points where the floor starts to act.
        procedure :: breakpoints => overlap_breakpoints
        !> Unclipped ramp r(xi).
        procedure :: ramp
    end type overlap_weight_t

contains

    !> Build the weight described by config; errors name the offending entry.
    subroutine make_weight(config, weight, error)
        !> The description.
        type(weight_config_t), intent(in) :: config
        !> The weight built.
        type(overlap_weight_t), intent(out) :: weight
        !> Set on an unknown shape, an empty overlap or a floor outside (0, 1/2).
        type(error_t), allocatable, intent(out) :: error
        character(len=200) :: buf
        if (.not. (config%alpha_min > 0 .and. config%alpha_min < 0.5_wp)) then
            write (buf, '(a,es11.3e3,a)') 'coupling weight: alpha_min = ', config%alpha_min, &
                ' must lie in (0, 0.5) (a coupled point with alpha = 0 or 1 makes the '// &
                'multiplier system singular); 1e-3 is a usual value'
            call make_error(error, trim(buf))
            return
        end if
        if (.not. (abs(config%s_particle - config%s_fe) > 0)) then
            call make_error(error, 'coupling weight: the overlap is empty (s_fe = s_particle);'// &
                            ' give two different ends')
            return
        end if
        select case (config%shape)
        case ('constant')
            if (.not. (config%constant >= config%alpha_min .and. &
                       config%constant <= 1 - config%alpha_min)) then
                write (buf, '(a,es23.15e3,a,es10.2e3,a)') 'coupling weight: constant = ', config%constant, &
                    ' must lie in [alpha_min, 1 - alpha_min] (alpha_min = ', config%alpha_min, ')'
                call make_error(error, trim(buf))
                return
            end if
            weight%coef = [config%constant, 0.0_wp, 0.0_wp, 0.0_wp]
        case ('linear')
            weight%coef = [1.0_wp, -1.0_wp, 0.0_wp, 0.0_wp]
        case ('cubic')
            weight%coef = [1.0_wp, 0.0_wp, -3.0_wp, 2.0_wp]
        case default
            call make_error(error, "coupling weight: unknown shape '"//trim(config%shape)// &
                            "' (expected constant, linear or cubic)")
            return
        end select
        weight%shape = config%shape
        weight%s_fe = config%s_fe
        weight%s_particle = config%s_particle
        weight%alpha_min = config%alpha_min
    end subroutine make_weight

    !> alpha(s): 1 before the overlap, 0 after it, the clipped ramp inside.
    pure real(wp) function overlap_value(self, s) result(alpha)
        !> The weight.
        class(overlap_weight_t), intent(in) :: self
        !> Curvilinear abscissa [m].
        real(wp), intent(in) :: s
        real(wp) :: xi, slack
        xi = (s - self%s_fe)/(self%s_particle - self%s_fe)
        ! the abscissa of a point placed on an end (a disk centred on s_fe or s_particle, as
        ! written in the deck) comes out of the node coordinates and element lengths rounded:
        ! within relative_roundoff of the larger end it is on that end, inside the overlap
        slack = relative_roundoff*max(abs(self%s_fe), abs(self%s_particle))/abs(self%s_particle - self%s_fe)
        if (xi < -slack) then
            alpha = 1.0_wp
        else if (xi > 1 + slack) then
            alpha = 0.0_wp
        else
            xi = min(max(xi, 0.0_wp), 1.0_wp)
            alpha = min(max(self%ramp(xi), self%alpha_min), 1.0_wp - self%alpha_min)
        end if
    end function overlap_value

    !> Overlap ends and the abscissas where the ramp meets the floor (the ramps are monotone,
    !> so each level is met at most once), sorted increasingly.
    pure function overlap_breakpoints(self) result(s)
        !> The weight.
        class(overlap_weight_t), intent(in) :: self
        real(wp), allocatable :: s(:)
        real(wp) :: xi(4)
        logical :: found
        integer :: n
        xi(1) = 0.0_wp
        xi(2) = 1.0_wp
        n = 2
        call ramp_crossing(self, 1.0_wp - self%alpha_min, xi(n + 1), found)
        if (found) n = n + 1
        call ramp_crossing(self, self%alpha_min, xi(n + 1), found)
        if (found) n = n + 1
        s = self%s_fe + xi(1:n)*(self%s_particle - self%s_fe)
        call sort_in_place(s)
    end function overlap_breakpoints

    !> The xi in (0, 1) where the ramp crosses level (bisection to the last bit); found is
    !> false when it does not cross it.
    pure subroutine ramp_crossing(self, level, xi, found)
        class(overlap_weight_t), intent(in) :: self
        real(wp), intent(in) :: level
        real(wp), intent(out) :: xi
        logical, intent(out) :: found
        real(wp) :: a, b, m, fa
        integer :: k
        a = 0.0_wp
        b = 1.0_wp
        xi = 0.0_wp
        fa = self%ramp(a) - level
        found = fa*(self%ramp(b) - level) < 0
        if (.not. found) return
        ! About 53 halvings of [0, 1] reach adjacent doubles; 200 is a safe cap.
        do k = 1, 200
            m = 0.5_wp*(a + b)
            if (m <= a .or. m >= b) exit
            if ((self%ramp(m) - level)*fa > 0) then
                a = m
            else
                b = m
            end if
        end do
        xi = 0.5_wp*(a + b)
    end subroutine ramp_crossing

    !> Unclipped ramp r(xi) = c0 + c1 xi + c2 xi^2 + c3 xi^3 (Horner).
    pure real(wp) function ramp(self, xi) result(r)
        !> The weight.
        class(overlap_weight_t), intent(in) :: self
        !> Reduced coordinate in the overlap, 0 at the FE end, 1 at the particle end.
        real(wp), intent(in) :: xi
        r = self%coef(0) + xi*(self%coef(1) + xi*(self%coef(2) + xi*self%coef(3)))
    end function ramp
end module coupling_weights
