!> How the contacts enter a Moreau-Jean step (doc/theory.md 2.3, 2.4): where they are
!> detected and their frames computed, which of them take part in the solve, and the normal
!> target of those that do. A family of rules:
!>   - `activation_predicted_t` (the default, deck `[time] contact_scheme = multicor`):
!>     detection on the mid configuration q + (1 - theta) h v; a contact is active when the
!>     free motion closes its gap, g + theta h u_n(free) <= 0 (up to a round-off allowance),
!>     or when it carried a compressive reaction at the previous step; Newton restitution
!>     when it closes, otherwise a gap term that lets it close its gap during the step but
!>     not overlap. A contact the free motion leaves open can still be shut by the impulses
!>     of the others: after the solve, the rule re-checks the contacts it left out on the
!>     end-of-step velocities, g + theta h u_n(end) < -allowance, lets those in with the gap
!>     term, and the step is solved again (`recheck`; dem_moreau_jean::mj_solve);
!>   - `activation_siconos_t` (`contact_scheme = siconos`): the step of Siconos 4.4's
!>     TimeStepping with MoreauJeanOSI and one Newton iteration, so that MULTICOR and Siconos
!>     integrate the same discrete problem. Siconos evaluates the contact geometry once per
!>     step, at the Newton iteration's starting point q + h v, and decides the active set from
!>     the output it computed there at the previous step: y + h/2 y' <= 0, with y the gap and
!>     y' the normal velocity at the start of the previous step, both in the previous step's
!>     geometry. An active contact takes u_n >= -e y' (Newton restitution on that velocity);
!>     there is no gap term, and no re-check: a contact left out stays out for the step, as
!>     in Siconos. Measured against Siconos 4.4 (doc/performance.md, "The same scheme as
!>     Siconos"): the trajectories agree to the solver's tolerance until its NSGS stops at its
!>     iteration cap.
!> Intact bonds are always active with Newton restitution, whatever the rule
!> (dem_contacts::contacts_set_laws).
module dem_activation
    use core_kinds, only: wp
    implicit none
    private
    public :: activation_t, activation_predicted_t, activation_siconos_t, pair_output_none

    !> Output of a pair that was not in the contact list of the previous step (it was farther
    !> than the alert distance): none (see siconos_decide).
    real(wp), parameter :: pair_output_none = huge(1.0_wp)

    !> A rule of activation (module header).
    type, abstract :: activation_t
    contains
        !> Where the contacts are detected: at q + offset h v (v the velocity at the start).
        procedure(offset_iface), deferred, nopass :: offset
        !> Whether a contact without a bond is active, and its normal target u_n >= target.
        procedure(decide_iface), deferred, nopass :: decide
        !> After the solve: whether a contact the rule left out (no bond, inactive) must be let
        !> in, from its end-of-step normal velocity, and its normal target then; the step is
        !> then solved again (dem_moreau_jean::mj_solve).
        procedure(recheck_iface), deferred, nopass :: recheck
        !> The deck word of the rule (`[time] contact_scheme`).
        procedure(name_iface), deferred, nopass :: name
    end type activation_t

    abstract interface
        pure real(wp) function offset_iface(theta) result(a)
            import :: wp
            !> Theta of the scheme.
            real(wp), intent(in) :: theta
        end function offset_iface

        pure subroutine decide_iface(h, theta, e, allowance, gap, un_begin, un_free, rn, y_prev, active, target)
            import :: wp
            !> Time step [s] and theta.
            real(wp), intent(in) :: h, theta
            !> Restitution coefficient of the pair.
            real(wp), intent(in) :: e
            !> Round-off allowance of the gap [m].
            real(wp), intent(in) :: allowance
            !> Gap at the detection configuration [m].
            real(wp), intent(in) :: gap
            !> Normal relative velocity at the start of the step and of the free motion [m/s].
            real(wp), intent(in) :: un_begin, un_free
            !> Normal reaction carried over from the previous step (warm start).
            real(wp), intent(in) :: rn
            !> Gap and normal velocity at the start of the previous step, in that step's
            !> geometry (pair_output_none, 0 for a pair new to the list).
            real(wp), intent(in) :: y_prev(2)
            !> The contact takes part in the solve.
            logical, intent(out) :: active
            !> Normal target u_n >= target of the step [m/s].
            real(wp), intent(out) :: target
        end subroutine decide_iface

        pure subroutine recheck_iface(h, theta, allowance, gap, un_end, reach, active, target)
            import :: wp
            !> Time step [s] and theta.
            real(wp), intent(in) :: h, theta
            !> Round-off allowance of the gap [m].
            real(wp), intent(in) :: allowance
            !> Gap at the detection configuration [m].
            real(wp), intent(in) :: gap
            !> Normal relative velocity at the end of the step, from the solve [m/s].
            real(wp), intent(in) :: un_end
            !> Gap [m] below which the contact is let in whether shut or not: within reach of
            !> the step's motion (0: only if shut).
            real(wp), intent(in) :: reach
            !> The contact must take part in the solve.
            logical, intent(out) :: active
            !> Normal target u_n >= target of the step [m/s] (when active).
            real(wp), intent(out) :: target
        end subroutine recheck_iface

        pure function name_iface() result(word)
            character(len=:), allocatable :: word
        end function name_iface
    end interface

    !> MULTICOR's rule: predicted gap on the mid configuration, gap term (module header).
    type, extends(activation_t) :: activation_predicted_t
    contains
        procedure, nopass :: offset => predicted_offset
        procedure, nopass :: decide => predicted_decide
        procedure, nopass :: recheck => predicted_recheck
        procedure, nopass :: name => predicted_name
    end type activation_predicted_t

    !> Siconos 4.4's rule (module header).
    type, extends(activation_t) :: activation_siconos_t
    contains
        procedure, nopass :: offset => siconos_offset
        procedure, nopass :: decide => siconos_decide
        procedure, nopass :: recheck => siconos_recheck
        procedure, nopass :: name => siconos_name
    end type activation_siconos_t

contains

    !> Mid configuration q + (1 - theta) h v: the end of the step is q + (1 - theta) h v +
    !> theta h v+, so the end-of-step gap is g + theta h u_n+ to first order.
    pure real(wp) function predicted_offset(theta) result(a)
        real(wp), intent(in) :: theta
        a = 1.0_wp - theta
    end function predicted_offset

    !> Active when g_p = g + theta h u_n(free) <= allowance, or when loaded at the previous
    !> step (rn > 0); target Newton e max(-u_n(begin), 0) when g_p <= 0, otherwise the gap
    !> term -max(g, 0)/(theta h) (the end-of-step gap g + theta h u_n+ >= 0).
    pure subroutine predicted_decide(h, theta, e, allowance, gap, un_begin, un_free, rn, y_prev, active, target)
        real(wp), intent(in) :: h, theta, e, allowance, gap, un_begin, un_free, rn, y_prev(2)
        logical, intent(out) :: active
        real(wp), intent(out) :: target
        real(wp) :: gp
        gp = gap + theta*h*un_free
        if (gp <= 0.0_wp) then
            target = e*max(-un_begin, 0.0_wp)
        else
            target = -max(gap, 0.0_wp)/(theta*h)
        end if
        active = gp <= allowance .or. rn > 0.0_wp
    end subroutine predicted_decide

    !> A contact left out whose end-of-step gap g + theta h u_n(end) is below -allowance (the
    !> predicted gap of predicted_decide on the solved velocities instead of the free ones):
    !> the other contacts' impulses shut it; or whose gap is below `reach`. It is let in with the gap term -max(g, 0)/(theta
    !> h), as an open contact of predicted_decide: it may close its gap but not overlap. The
    !> allowance on the other side (-allowance, where predicted_decide lets in at +allowance)
    !> leaves out contacts that end touching to the rounding of the coordinates.
    pure subroutine predicted_recheck(h, theta, allowance, gap, un_end, reach, active, target)
        real(wp), intent(in) :: h, theta, allowance, gap, un_end, reach
        logical, intent(out) :: active
        real(wp), intent(out) :: target
        active = gap + theta*h*un_end < -allowance .or. gap < reach
        target = -max(gap, 0.0_wp)/(theta*h)
    end subroutine predicted_recheck

    !> The deck's word for the predicted-gap rule ('multicor').
    pure function predicted_name() result(word)
        character(len=:), allocatable :: word
        word = 'multicor'
    end function predicted_name

    !> Siconos evaluates the geometry at the Newton iteration's starting point q + h v.
    pure real(wp) function siconos_offset(theta) result(a)
        real(wp), intent(in) :: theta
        ! the same for every theta (the starting point is q + h v in Siconos)
        a = 1.0_wp
    end function siconos_offset

    !> Active when y + h/2 y' <= 0 (Siconos' activation with gamma = 1/2 and threshold 0) on
    !> the previous step's output (y, y') = y_prev; target -e y'. A pair new to the list has
    !> no output yet: it takes the one extrapolated back from this step's geometry, (g - h u_n,
    !> u_n) (q + h v moves by about h v from one step to the next). Such a pair was beyond the
    !> alert distance at the previous step, so that extrapolation leaves it inactive, as in
    !> Siconos, unless it closes by more than the alert distance in half a step; then it is
    !> the nearest guess of the output Siconos would have.
    pure subroutine siconos_decide(h, theta, e, allowance, gap, un_begin, un_free, rn, y_prev, active, target)
        real(wp), intent(in) :: h, theta, e, allowance, gap, un_begin, un_free, rn, y_prev(2)
        logical, intent(out) :: active
        real(wp), intent(out) :: target
        real(wp) :: y(2)
        y = y_prev
        if (y_prev(1) >= pair_output_none) y = [gap - h*un_begin, un_begin]
        active = y(1) + 0.5_wp*h*y(2) <= 0.0_wp
        target = -e*y(2)
    end subroutine siconos_decide

    !> No re-check (active is false): Siconos decides the active set once per step, before the
    !> solve (its contacts left out may overlap within the step, doc/theory.md 2.6).
    pure subroutine siconos_recheck(h, theta, allowance, gap, un_end, reach, active, target)
        real(wp), intent(in) :: h, theta, allowance, gap, un_end, reach
        logical, intent(out) :: active
        real(wp), intent(out) :: target
        active = .false.
        target = 0.0_wp
    end subroutine siconos_recheck

    !> The deck's word for Siconos' rule ('siconos').
    pure function siconos_name() result(word)
        character(len=:), allocatable :: word
        word = 'siconos'
    end function siconos_name

end module dem_activation
