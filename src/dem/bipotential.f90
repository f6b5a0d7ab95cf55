!> Local solver of the Signorini-Coulomb law with De Saxce's bi-potential (THEORY.md 1).
!>
!> Local unknowns of one contact: reaction r = (r_n, r_t) (impulse) and relative velocity
!> u = (u_n, u_t) = b + W r, with W the 2x2 local Delassus block. Convention: r_n >= 0 is
!> compression, u_n > 0 opening. The law is the fixed point
!>     r = proj_K(r - rho u_hat),  u_hat = (u_n + mu |u_t|, u_t),  K = {|r_t| <= mu r_n}.
!> Prediction-correction: predictor tau = r - rho u_hat, corrector = projection on the cone
!> (three cases: separation, stick, slip).
!>
!> Choice of rho: the fixed point holds for a scalar rho only (with rho_n /= rho_t it is not
!> the Coulomb law in slip). We iterate in the scaled frame r' = (sqrt(W_nn) r_n,
!> sqrt(W_tt) r_t), u' = (u_n/sqrt(W_nn), u_t/sqrt(W_tt)), where W' has a unit diagonal,
!> the cone becomes K_mu' with mu' = mu sqrt(W_tt/W_nn), and u_hat' is De Saxce's modified
!> velocity with mu' (the law is invariant under this change of variables). There rho = 1
!> (= 1/W'_nn): in the original variables rho_n = 1/W_nn, rho_t = 1/W_tt with the
!> projection taken in the metric diag(W_nn, W_tt). Separation and stick converge in two
!> iterations when W_nt = 0 (a coupling W_nt contracts at rate |W_nt|/sqrt(W_nn W_tt) < 1).
!> Slip with rho = 1 only contracts at rate mu'^2/(1 + mu'^2); after a slip projection the
!> step rho = (1 + mu'^2)/(1 + c s mu') (see slip_branch) reaches the slip solution at once,
!> and is kept when it satisfies the law; likewise after a stick projection the stick solution
!> u = 0 (the limit of the stick branch) is kept when it lies in the cone. The iterations
!> thus pick the branch and each branch is then solved exactly: 1 to 3 iterations per solve.
module dem_bipotential
    use core_kinds, only: wp
    implicit none
    private
    public :: bipotential_predictor, coulomb_projection, bipotential_local_solve
    public :: bipotential_residual, case_separation, case_stick, case_slip
    public :: bipotential_scaling, bipotential_local_solve_scaled, bipotential_n_scaling

    !> Projection case: separation (r = 0).
    integer, parameter :: case_separation = 1
    !> Projection case: stick (tau inside the cone).
    integer, parameter :: case_stick = 2
    !> Projection case: slip (r on the boundary of the cone).
    integer, parameter :: case_slip = 3
    !> Number of constants per contact computed by `bipotential_scaling`.
    integer, parameter :: bipotential_n_scaling = 8

contains

    !> Predictor tau = r - rho u_hat with De Saxce's modified velocity u_hat.
    pure elemental subroutine bipotential_predictor(rn, rt, un, ut, mu, rho, taun, taut)
        !> Current reaction (normal, tangential).
        real(wp), intent(in) :: rn, rt
        !> Current relative velocity (normal, tangential).
        real(wp), intent(in) :: un, ut
        !> Friction coefficient.
        real(wp), intent(in) :: mu
        !> Scalar step (> 0).
        real(wp), intent(in) :: rho
        !> Predicted reaction.
        real(wp), intent(out) :: taun, taut
        taun = rn - rho*(un + mu*abs(ut))
        taut = rt - rho*ut
    end subroutine bipotential_predictor

    !> Corrector: Euclidean projection of tau on the cone |r_t| <= mu r_n.
    pure elemental subroutine coulomb_projection(taun, taut, mu, rn, rt, pcase)
        !> Predicted reaction (normal, tangential).
        real(wp), intent(in) :: taun, taut
        !> Friction coefficient (>= 0).
        real(wp), intent(in) :: mu
        !> Projected reaction.
        real(wp), intent(out) :: rn, rt
        !> case_separation, case_stick or case_slip.
        integer, intent(out) :: pcase
        if (mu*abs(taut) <= -taun) then
            rn = 0.0_wp
            rt = 0.0_wp
            pcase = case_separation
        else if (abs(taut) <= mu*taun) then
            rn = taun
            rt = taut
            pcase = case_stick
        else
            rn = (taun + mu*abs(taut))/(1.0_wp + mu*mu)
            rt = sign(mu*rn, taut)
            pcase = case_slip
        end if
    end subroutine coulomb_projection

    !> Solve the local law for r given u = b + W r: predictor-corrector iterations in the
    !> scaled frame (rho = 1 there), from the given r, until the change of r' is at most
    !> tol |r'| or max_iter iterations. W must be positive semi-definite; a contact with
    !> W_nn + W_tt = 0 (both bodies immobile) is left unchanged.
    pure elemental subroutine bipotential_local_solve(wnn, wnt, wtt, bn, bt, mu, tol, max_iter, &
                                                      rn, rt, n_iter, pcase)
        !> Delassus block entries.
        real(wp), intent(in) :: wnn, wnt, wtt
        !> Velocity without this contact's reaction (normal, tangential).
        real(wp), intent(in) :: bn, bt
        !> Friction coefficient (>= 0).
        real(wp), intent(in) :: mu
        !> Relative tolerance on the change of the scaled reaction.
        real(wp), intent(in) :: tol
        !> Iteration cap (>= 1).
        integer, intent(in) :: max_iter
        !> Reaction: initial guess in, solution out.
        real(wp), intent(inout) :: rn, rt
        !> Iterations done.
        integer, intent(out) :: n_iter
        !> Case of the last projection.
        integer, intent(out) :: pcase
        real(wp) :: sc(bipotential_n_scaling)
        call bipotential_scaling(wnn, wnt, wtt, mu, sc)
        call bipotential_local_solve_scaled(sc, bn, bt, tol, max_iter, rn, rt, n_iter, pcase)
    end subroutine bipotential_local_solve

    !> Constants of the scaled frame of one contact, for bipotential_local_solve_scaled:
    !> sc = (s_n, s_t, 1/s_n, 1/s_t, c, mu', 1/(1 + mu'^2), 1/(1 - c^2) or 0 when c^2 >= 1), with
    !> s_n = sqrt(W_nn), s_t = sqrt(W_tt) (floored, see `scaling`), c = W_nt/(s_n s_t) and
    !> mu' = mu s_t/s_n; all zero when W_nn + W_tt <= 0 (both bodies immobile).
    pure subroutine bipotential_scaling(wnn, wnt, wtt, mu, sc)
        !> Delassus block entries.
        real(wp), intent(in) :: wnn, wnt, wtt
        !> Friction coefficient (>= 0).
        real(wp), intent(in) :: mu
        !> The constants.
        real(wp), intent(out) :: sc(bipotential_n_scaling)
        sc = 0.0_wp
        if (wnn + wtt <= 0.0_wp) return
        call scaling(wnn, wnt, wtt, mu, sc(1), sc(2), sc(5), sc(6))
        sc(3) = 1.0_wp/sc(1)
        sc(4) = 1.0_wp/sc(2)
        sc(7) = 1.0_wp/(1.0_wp + sc(6)**2)
        if (1.0_wp - sc(5)**2 > 0.0_wp) sc(8) = 1.0_wp/(1.0_wp - sc(5)**2)
    end subroutine bipotential_scaling

    !> `bipotential_local_solve` with the constants of the scaled frame computed beforehand by
    !> `bipotential_scaling` (the NLGS computes them once per contact and solve). The
    !> projection on the cone is written out here (multiplying by 1/(1 + mu'^2) instead of
    !> dividing): this is the innermost loop of the solver.
    pure subroutine bipotential_local_solve_scaled(sc, bn, bt, tol, max_iter, rn, rt, n_iter, pcase)
        !> Constants of the scaled frame (`bipotential_scaling`).
        real(wp), intent(in) :: sc(bipotential_n_scaling)
        !> Velocity without this contact's reaction (normal, tangential).
        real(wp), intent(in) :: bn, bt
        !> Relative tolerance on the change of the scaled reaction.
        real(wp), intent(in) :: tol
        !> Iteration cap (>= 1).
        integer, intent(in) :: max_iter
        !> Reaction: initial guess in, solution out (unchanged when sc(1) = 0).
        real(wp), intent(inout) :: rn, rt
        !> Iterations done.
        integer, intent(out) :: n_iter
        !> Case of the last projection.
        integer, intent(out) :: pcase
        real(wp) :: c, mup, bnp, btp, rnp, rtp, unp, utp, taun, taut, qn, qt, change
        logical :: done
        pcase = case_separation
        n_iter = 0
        if (sc(1) <= 0.0_wp) return
        c = sc(5)
        mup = sc(6)
        bnp = bn*sc(3)
        btp = bt*sc(4)
        rnp = rn*sc(1)
        rtp = rt*sc(2)
        do n_iter = 1, max_iter
            unp = bnp + rnp + c*rtp
            utp = btp + c*rnp + rtp
            taun = rnp - (unp + mup*abs(utp))
            taut = rtp - utp
            if (mup*abs(taut) <= -taun) then
                qn = 0.0_wp
                qt = 0.0_wp
                pcase = case_separation
            else if (abs(taut) <= mup*taun) then
                qn = taun
                qt = taut
                pcase = case_stick
            else
                qn = (taun + mup*abs(taut))*sc(7)
                qt = sign(mup*qn, taut)
                pcase = case_slip
            end if
            change = abs(qn - rnp) + abs(qt - rtp)
            rnp = qn
            rtp = qt
            if (change <= tol*(abs(rnp) + abs(rtp))) exit
            done = .false.
            if (pcase == case_slip) then
                call slip_branch(bnp, btp, c, mup, rnp, rtp, done)
            else if (pcase == case_stick) then
                call stick_branch(bnp, btp, c, mup, sc(8), rnp, rtp, done)
            end if
            if (done) exit
        end do
        n_iter = min(n_iter, max_iter)
        rn = rnp*sc(3)
        rt = rtp*sc(4)
    end subroutine bipotential_local_solve_scaled

    !> Slip acceleration (scaled frame). After a slip projection r lies on the cone boundary,
    !> r_t = s mu' r_n (s = sign of r_t). Along that branch the predictor-corrector step with
    !> rho = (1 + mu'^2)/(1 + c s mu') lands in one iteration on r_n = -b_n/(1 + c s mu'),
    !> where u_n = 0. That point is accepted only if it satisfies the law (r_n >= 0, sliding
    !> against r_t: u_t r_t < 0, slope 1 + c s mu' > 0); `done` tells whether it was.
    pure subroutine slip_branch(bnp, btp, c, mup, rnp, rtp, done)
        real(wp), intent(in) :: bnp, btp, c, mup
        real(wp), intent(inout) :: rnp, rtp
        logical, intent(out) :: done
        real(wp) :: s, slope, qn, qt
        done = .false.
        s = sign(1.0_wp, rtp)
        slope = 1.0_wp + c*s*mup
        if (slope <= 0.0_wp) return
        qn = -bnp/slope
        qt = s*mup*qn
        if (qn < 0.0_wp .or. (btp + c*qn + qt)*s >= 0.0_wp) return
        rnp = qn
        rtp = qt
        done = .true.
    end subroutine slip_branch

    !> Stick acceleration (scaled frame). After a stick projection, the stick solution
    !> u = 0, r' = -W'^-1 b' is the limit of the stick branch (rate |c| with rho = 1); it is
    !> accepted when it lies in the cone, i.e. when it satisfies the law. inv_det = 1/(1 - c^2),
    !> 0 when W' is singular (no acceleration then).
    pure subroutine stick_branch(bnp, btp, c, mup, inv_det, rnp, rtp, done)
        real(wp), intent(in) :: bnp, btp, c, mup, inv_det
        real(wp), intent(inout) :: rnp, rtp
        logical, intent(out) :: done
        real(wp) :: qn, qt
        done = .false.
        if (inv_det <= 0.0_wp) return
        qn = (-bnp + c*btp)*inv_det
        qt = (-btp + c*bnp)*inv_det
        if (abs(qt) > mup*qn) return
        rnp = qn
        rtp = qt
        done = .true.
    end subroutine stick_branch

    !> Residual of the law at (r, u) measured in the scaled frame:
    !> |r' - proj(r' - u_hat')| (units of r' = sqrt(W) r). Zero iff (r, u) satisfies the law.
    pure elemental real(wp) function bipotential_residual(wnn, wnt, wtt, un, ut, mu, rn, rt) result(res)
        !> Delassus block entries.
        real(wp), intent(in) :: wnn, wnt, wtt
        !> Relative velocity (normal, tangential).
        real(wp), intent(in) :: un, ut
        !> Friction coefficient.
        real(wp), intent(in) :: mu
        !> Reaction (normal, tangential).
        real(wp), intent(in) :: rn, rt
        real(wp) :: sn, st, c, mup, taun, taut, qn, qt
        integer :: pcase
        res = 0.0_wp
        if (wnn + wtt <= 0.0_wp) return
        call scaling(wnn, wnt, wtt, mu, sn, st, c, mup)
        call bipotential_predictor(rn*sn, rt*st, un/sn, ut/st, mup, 1.0_wp, taun, taut)
        call coulomb_projection(taun, taut, mup, qn, qt, pcase)
        res = hypot(rn*sn - qn, rt*st - qt)
    end function bipotential_residual

    !> Scale factors of the frame where W has a unit diagonal (diagonal floored at 1e-12 of
    !> the trace so that a direction blocked by fixities does not divide by zero).
    pure subroutine scaling(wnn, wnt, wtt, mu, sn, st, c, mup)
        real(wp), intent(in) :: wnn, wnt, wtt, mu
        real(wp), intent(out) :: sn, st, c, mup
        real(wp) :: floor
        floor = 1.0e-12_wp*(wnn + wtt)
        sn = sqrt(max(wnn, floor))
        st = sqrt(max(wtt, floor))
        c = wnt/(sn*st)
        mup = mu*st/sn
    end subroutine scaling
end module dem_bipotential
