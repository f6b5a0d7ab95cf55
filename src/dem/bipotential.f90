!> Local solver of the Signorini-Coulomb law with De Saxce's bi-potential (doc/theory.md section 3).
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
    use core_constants, only: diagonal_floor, singular_ratio
    implicit none
    private
    public :: bipotential_predictor, coulomb_projection, bipotential_local_solve
    public :: bipotential_residual, case_separation, case_stick, case_slip
    public :: bipotential_scaling, bipotential_local_solve_scaled, bipotential_n_scaling
    public :: rolling_projection, rolling_local_solve, rolling_scaling, rolling_local_solve_scaled
    public :: rolling_residual, rolling_n_scaling, case_roll, case_slip_roll

    !> Projection case: separation (r = 0).
    integer, parameter :: case_separation = 1
    !> Projection case: stick (tau inside the cone).
    integer, parameter :: case_stick = 2
    !> Projection case: slip (r on the boundary of the cone).
    integer, parameter :: case_slip = 3
    !> Projection case of the rolling cone: |M| = e r_n, |r_t| < mu r_n (rolling, no sliding).
    integer, parameter :: case_roll = 4
    !> Projection case of the rolling cone: both bounds reached (sliding and rolling).
    integer, parameter :: case_slip_roll = 5
    !> Number of constants per contact computed by `bipotential_scaling`.
    integer, parameter :: bipotential_n_scaling = 8
    !> Number of constants per contact computed by `rolling_scaling`.
    integer, parameter :: rolling_n_scaling = 18
    !> Floor of a diagonal entry of W relative to its trace, so that a direction held by the
    !> fixities does not divide by zero (the floored direction then barely responds).
    real(wp), parameter :: scaling_floor = diagonal_floor
    !> Determinant below which a scaled block (unit diagonal) is treated as singular and its
    !> branch is not solved directly (the iterations still converge, only slower).
    real(wp), parameter :: singular_det = singular_ratio

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
    !> dividing): this is the innermost loop of the solver. When b_n >= 0 the reaction is zero
    !> at once: r = 0 satisfies the law (u = b, u_n >= 0, so the De Saxce velocity
    !> (u_n + mu |u_t|, u_t) lies in the dual cone), and the iterations reach it from a
    !> reaction in slip only at the rate mu'^2/(1 + mu'^2) per iteration: under mu = 1000
    !> (1 - 3e-7) the change per sweep passed the tolerance, and a grazing impact kept its
    !> sliding warm start and rebounded 26 times too fast, every step reported converged.
    !> Where a large mu lets the law have other solutions too, the free separation is taken.
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
        if (bnp >= 0.0_wp) then
            ! separation, exactly (above)
            rn = 0.0_wp
            rt = 0.0_wp
            n_iter = 1
            return
        end if
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
        ! (sqrt rather than hypot: the scaled reactions are far from overflow, and libm's
        ! hypot was 1.4 % of the 200-disk deposit's time, in the residual of every step)
        res = sqrt((rn*sn - qn)**2 + (rt*st - qt)**2)
    end function bipotential_residual

    !> Scale factors of the frame where W has a unit diagonal (diagonal floored at 1e-12 of
    !> the trace so that a direction blocked by fixities does not divide by zero).
    pure subroutine scaling(wnn, wnt, wtt, mu, sn, st, c, mup)
        real(wp), intent(in) :: wnn, wnt, wtt, mu
        real(wp), intent(out) :: sn, st, c, mup
        real(wp) :: floor
        floor = scaling_floor*(wnn + wtt)
        sn = sqrt(max(wnn, floor))
        st = sqrt(max(wtt, floor))
        c = wnt/(sn*st)
        mup = mu*st/sn
    end subroutine scaling
    ! ---------------------------------------------------------------------------------------
    ! Three-component law (r_n, r_t, M): Signorini, Coulomb and rolling resistance
    ! (doc/theory.md, "Rolling resistance and bonded contacts"). The cone is
    !     K = {|r_t| <= mu r_n, |M| <= e r_n},  e a length,
    ! De Saxce's modified velocity u_hat = (u_n + mu |u_t| + e |w_r|, u_t, w_r) and the law is
    ! r = proj_K(r - rho u_hat). As for two components the iterations run in the frame where
    ! the 3x3 block W has a unit diagonal: r' = D r, u' = D^-1 u, D = diag(sqrt(W_nn),
    ! sqrt(W_tt), sqrt(W_mm)); there mu' = mu sqrt(W_tt/W_nn), e' = e sqrt(W_mm/W_nn) (both
    ! dimensionless: M is scaled by a length). The scaled block has a unit diagonal but, unlike a
    ! 2x2 one, its largest eigenvalue may reach 3, beyond the 2/rho that a fixed-point step
    ! rho = 1 tolerates: rho = 1/(1 + largest off-diagonal row sum) (Gershgorin: rho
    ! lambda_max <= 1). After each projection the branch it landed on (stick, slip, roll, slip
    ! and roll) is solved exactly and kept when it satisfies the law.
    ! ---------------------------------------------------------------------------------------

    !> Euclidean projection of (taun, taut, taum) on K = {|t| <= mu n, |m| <= e n} (mu, e >= 0).
    !> The five cases are the active sets of the projection's optimality conditions:
    !> separation (apex), stick (interior), slip (|t| face), roll (|m| face), slip and roll
    !> (the edge where both faces meet).
    pure elemental subroutine rolling_projection(taun, taut, taum, mu, e, rn, rt, rm, pcase)
        !> Point to project (normal, tangential, moment component).
        real(wp), intent(in) :: taun, taut, taum
        !> Friction coefficient and rolling length of the cone (in consistent units).
        real(wp), intent(in) :: mu, e
        !> Projection.
        real(wp), intent(out) :: rn, rt, rm
        !> case_separation, case_stick, case_slip, case_roll or case_slip_roll.
        integer, intent(out) :: pcase
        real(wp) :: at, am, n1
        at = abs(taut)
        am = abs(taum)
        if (mu*at + e*am <= -taun) then
            rn = 0.0_wp
            rt = 0.0_wp
            rm = 0.0_wp
            pcase = case_separation
            return
        end if
        if (at <= mu*taun .and. am <= e*taun) then
            rn = taun
            rt = taut
            rm = taum
            pcase = case_stick
            return
        end if
        n1 = (taun + mu*at + e*am)/(1.0_wp + mu*mu + e*e)
        if (at > mu*n1 .and. am > e*n1) then
            rn = n1
            rt = sign(mu*n1, taut)
            rm = sign(e*n1, taum)
            pcase = case_slip_roll
            return
        end if
        n1 = (taun + mu*at)/(1.0_wp + mu*mu)
        if (am <= e*n1) then
            rn = n1
            rt = sign(mu*n1, taut)
            rm = taum
            pcase = case_slip
            return
        end if
        n1 = (taun + e*am)/(1.0_wp + e*e)
        rn = n1
        rt = taut
        rm = sign(e*n1, taum)
        pcase = case_roll
    end subroutine rolling_projection

    !> Solve the three-component law for r given u = b + W r (W symmetric positive
    !> semi-definite, w = (W_nn, W_nt, W_tt, W_nm, W_tm, W_mm)), from the given r, until the
    !> change of the scaled reaction is at most tol times its size or max_iter iterations.
    pure subroutine rolling_local_solve(w, b, mu, e, tol, max_iter, r, n_iter, pcase)
        !> Delassus block (nn, nt, tt, nm, tm, mm).
        real(wp), intent(in) :: w(6)
        !> Velocity without this contact's reaction (u_n, u_t, w_r).
        real(wp), intent(in) :: b(3)
        !> Friction coefficient and rolling length [m] (>= 0).
        real(wp), intent(in) :: mu, e
        !> Relative tolerance of the local iterations.
        real(wp), intent(in) :: tol
        !> Iteration cap (>= 1).
        integer, intent(in) :: max_iter
        !> Reaction (r_n, r_t, M): initial guess in, solution out.
        real(wp), intent(inout) :: r(3)
        !> Iterations done.
        integer, intent(out) :: n_iter
        !> Case of the last projection.
        integer, intent(out) :: pcase
        real(wp) :: sc(rolling_n_scaling)
        call rolling_scaling(w, mu, e, sc)
        call rolling_local_solve_scaled(sc, b, tol, max_iter, r, n_iter, pcase)
    end subroutine rolling_local_solve

    !> Constants of the scaled frame of one three-component contact: sc = (s_n, s_t, s_m,
    !> 1/s_n, 1/s_t, 1/s_m, c_nt, c_nm, c_tm, mu', e', inverse of the scaled block (6 entries:
    !> nn, nt, tt, nm, tm, mm; zero when it is singular), rho); all zero when the trace of W is 0.
    pure subroutine rolling_scaling(w, mu, e, sc)
        !> Delassus block (nn, nt, tt, nm, tm, mm).
        real(wp), intent(in) :: w(6)
        !> Friction coefficient and rolling length [m].
        real(wp), intent(in) :: mu, e
        !> The constants.
        real(wp), intent(out) :: sc(rolling_n_scaling)
        real(wp) :: fl_force, fl_moment, a, bb, d, det
        sc = 0.0_wp
        if (w(1) + w(3) + w(6) <= 0.0_wp) return
        ! A direction held by the fixities has a zero diagonal: floor it as in `scaling`, the
        ! force directions on their own scale and the moment on its own (W_nn and W_tt are in
        ! 1/kg, W_mm in 1/(kg m^2): a common floor would depend on the unit of length and, for
        ! disks of 1 micrometre in metres, exceed W_nn). A group held entirely takes the other's
        ! floor: its row and column are zero, and any scale gives the same solution.
        fl_force = scaling_floor*(w(1) + w(3))
        fl_moment = scaling_floor*w(6)
        if (fl_force <= 0.0_wp) fl_force = fl_moment
        if (fl_moment <= 0.0_wp) fl_moment = fl_force
        sc(1) = sqrt(max(w(1), fl_force))
        sc(2) = sqrt(max(w(3), fl_force))
        sc(3) = sqrt(max(w(6), fl_moment))
        sc(4:6) = 1.0_wp/sc(1:3)
        a = w(2)*sc(4)*sc(5)
        bb = w(4)*sc(4)*sc(6)
        d = w(5)*sc(5)*sc(6)
        sc(7) = a
        sc(8) = bb
        sc(9) = d
        sc(10) = mu*sc(2)*sc(4)
        sc(11) = e*sc(3)*sc(4)
        sc(18) = 1.0_wp/(1.0_wp + max(abs(a) + abs(bb), abs(a) + abs(d), abs(bb) + abs(d)))
        ! inverse of [1 a b; a 1 d; b d 1] by cofactors
        det = 1.0_wp + 2.0_wp*a*bb*d - a*a - bb*bb - d*d
        if (det > singular_det) then
            sc(12) = (1.0_wp - d*d)/det
            sc(13) = (bb*d - a)/det
            sc(14) = (1.0_wp - bb*bb)/det
            sc(15) = (a*d - bb)/det
            sc(16) = (a*bb - d)/det
            sc(17) = (1.0_wp - a*a)/det
        end if
    end subroutine rolling_scaling

    !> `rolling_local_solve` with the constants of `rolling_scaling` computed beforehand.
    pure subroutine rolling_local_solve_scaled(sc, b, tol, max_iter, r, n_iter, pcase)
        !> Constants of the scaled frame (`rolling_scaling`).
        real(wp), intent(in) :: sc(rolling_n_scaling)
        !> Velocity without this contact's reaction (u_n, u_t, w_r).
        real(wp), intent(in) :: b(3)
        !> Relative tolerance of the local iterations.
        real(wp), intent(in) :: tol
        !> Iteration cap (>= 1).
        integer, intent(in) :: max_iter
        !> Reaction (r_n, r_t, M): initial guess in, solution out (unchanged when sc(1) = 0).
        real(wp), intent(inout) :: r(3)
        !> Iterations done.
        integer, intent(out) :: n_iter
        !> Case of the last projection.
        integer, intent(out) :: pcase
        real(wp) :: bp(3), rp(3), up(3), tau(3), q(3), change
        logical :: done
        pcase = case_separation
        n_iter = 0
        if (sc(1) <= 0.0_wp) return
        bp = b*sc(4:6)
        if (bp(1) >= 0.0_wp) then
            ! separation, exactly (as in bipotential_local_solve_scaled)
            r = 0.0_wp
            n_iter = 1
            return
        end if
        rp = r*sc(1:3)
        done = .false.
        do n_iter = 1, max_iter
            up = scaled_velocity(sc, bp, rp)
            tau(1) = rp(1) - sc(18)*(up(1) + sc(10)*abs(up(2)) + sc(11)*abs(up(3)))
            tau(2:3) = rp(2:3) - sc(18)*up(2:3)
            call rolling_projection(tau(1), tau(2), tau(3), sc(10), sc(11), q(1), q(2), q(3), pcase)
            change = sum(abs(q - rp))
            rp = q
            if (change <= tol*sum(abs(rp))) then
                done = .true.
                exit
            end if
            if (pcase == case_separation) cycle
            call branch(sc, bp, pcase, rp, done)
            if (done) exit
        end do
        n_iter = min(n_iter, max_iter)
        ! The iterations stopped at the cap: the branch they were heading for may be one the
        ! projections keep missing (a strong coupling of t and M with a wide cone contracts at
        ! a rate close to 1). Every branch solved exactly, and the one satisfying the law kept.
        if (.not. done) call exact_branches(sc, bp, rp, pcase)
        r = rp*sc(4:6)
    end subroutine rolling_local_solve_scaled

    !> Every branch of the three-component law solved exactly (`branch`): separation (valid
    !> when b'_n >= 0), stick, slip with either sign, roll with either sign, slip and roll with
    !> the four; rp becomes the candidate that satisfies the whole law nearest to it (in the
    !> scaled frame), pcase its case. Unchanged when no candidate does (a singular block).
    pure subroutine exact_branches(sc, bp, rp, pcase)
        real(wp), intent(in) :: sc(rolling_n_scaling), bp(3)
        real(wp), intent(inout) :: rp(3)
        integer, intent(inout) :: pcase
        integer, parameter :: n_cand = 9
        integer, parameter :: cases(n_cand) = [case_stick, case_slip, case_slip, case_roll, case_roll, &
                                               case_slip_roll, case_slip_roll, case_slip_roll, case_slip_roll]
        ! signs of r'_t and M' that `branch` takes for each candidate (unused where irrelevant)
        real(wp), parameter :: st(n_cand) = [1.0_wp, 1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp, 1.0_wp, -1.0_wp]
        real(wp), parameter :: sm(n_cand) = [1.0_wp, 1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp, -1.0_wp]
        real(wp) :: q(3), best(3), dist, best_dist
        integer :: k, best_case
        logical :: done
        best_dist = huge(1.0_wp)
        best_case = 0
        if (bp(1) >= 0.0_wp) then
            best = 0.0_wp
            best_dist = sum((rp - best)**2)
            best_case = case_separation
        end if
        do k = 1, n_cand
            q = [0.0_wp, st(k), sm(k)]
            call branch(sc, bp, cases(k), q, done)
            if (.not. done) cycle
            dist = sum((rp - q)**2)
            if (dist < best_dist) then
                best = q
                best_dist = dist
                best_case = cases(k)
            end if
        end do
        if (best_case == 0) return
        rp = best
        pcase = best_case
    end subroutine exact_branches

    !> u' = b' + W' r' in the scaled frame.
    pure function scaled_velocity(sc, bp, rp) result(up)
        real(wp), intent(in) :: sc(rolling_n_scaling), bp(3), rp(3)
        real(wp) :: up(3)
        up(1) = bp(1) + rp(1) + sc(7)*rp(2) + sc(8)*rp(3)
        up(2) = bp(2) + sc(7)*rp(1) + rp(2) + sc(9)*rp(3)
        up(3) = bp(3) + sc(8)*rp(1) + sc(9)*rp(2) + rp(3)
    end function scaled_velocity

    !> Exact solution of the branch of the law on which the last projection landed (scaled
    !> frame), kept (done) only when it satisfies the whole law:
    !>  - stick: u' = 0, r' = -W'^-1 b', inside the cone;
    !>  - slip: r' = (n, s mu' n, m), u'_n = u'_m = 0, with n >= 0, |m| <= e' n, s u'_t <= 0;
    !>  - roll: r' = (n, t, s e' n), u'_n = u'_t = 0, with n >= 0, |t| <= mu' n, s u'_m <= 0;
    !>  - slip and roll: r' = n (1, s mu', s' e'), u'_n = 0, n >= 0, s u'_t <= 0, s' u'_m <= 0.
    !> (s, s' are the signs of the projected r'_t, M'.)
    pure subroutine branch(sc, bp, pcase, rp, done)
        real(wp), intent(in) :: sc(rolling_n_scaling), bp(3)
        integer, intent(in) :: pcase
        real(wp), intent(inout) :: rp(3)
        logical, intent(out) :: done
        real(wp) :: q(3), up(3), mup, ep, s, sm, a11, a12, a21, a22, det, x1, x2
        done = .false.
        mup = sc(10)
        ep = sc(11)
        s = sign(1.0_wp, rp(2))
        sm = sign(1.0_wp, rp(3))
        select case (pcase)
        case (case_stick)
            if (sc(12) <= 0.0_wp) return
            q(1) = -(sc(12)*bp(1) + sc(13)*bp(2) + sc(15)*bp(3))
            q(2) = -(sc(13)*bp(1) + sc(14)*bp(2) + sc(16)*bp(3))
            q(3) = -(sc(15)*bp(1) + sc(16)*bp(2) + sc(17)*bp(3))
            if (abs(q(2)) > mup*q(1) .or. abs(q(3)) > ep*q(1)) return
        case (case_slip)
            ! unknowns (n, m): rows u'_n = 0 and u'_m = 0
            a11 = 1.0_wp + sc(7)*s*mup
            a12 = sc(8)
            a21 = sc(8) + sc(9)*s*mup
            a22 = 1.0_wp
            det = a11*a22 - a12*a21
            if (det <= singular_det) return
            x1 = (-bp(1)*a22 + a12*bp(3))/det
            x2 = (-a11*bp(3) + a21*bp(1))/det
            q = [x1, s*mup*x1, x2]
            if (x1 < 0.0_wp .or. abs(x2) > ep*x1) return
            up = scaled_velocity(sc, bp, q)
            if (s*up(2) > 0.0_wp) return
        case (case_roll)
            ! unknowns (n, t): rows u'_n = 0 and u'_t = 0
            a11 = 1.0_wp + sc(8)*sm*ep
            a12 = sc(7)
            a21 = sc(7) + sc(9)*sm*ep
            a22 = 1.0_wp
            det = a11*a22 - a12*a21
            if (det <= singular_det) return
            x1 = (-bp(1)*a22 + a12*bp(2))/det
            x2 = (-a11*bp(2) + a21*bp(1))/det
            q = [x1, x2, sm*ep*x1]
            if (x1 < 0.0_wp .or. abs(x2) > mup*x1) return
            up = scaled_velocity(sc, bp, q)
            if (sm*up(3) > 0.0_wp) return
        case (case_slip_roll)
            a11 = 1.0_wp + sc(7)*s*mup + sc(8)*sm*ep
            if (a11 <= 0.0_wp) return
            x1 = -bp(1)/a11
            q = [x1, s*mup*x1, sm*ep*x1]
            if (x1 < 0.0_wp) return
            up = scaled_velocity(sc, bp, q)
            if (s*up(2) > 0.0_wp .or. sm*up(3) > 0.0_wp) return
        case default
            return
        end select
        rp = q
        done = .true.
    end subroutine branch

    !> Residual of the three-component law at (r, u), in the scaled frame:
    !> |r' - proj(r' - u_hat')|. Zero iff (r, u) satisfies the law.
    pure real(wp) function rolling_residual(w, u, mu, e, r) result(res)
        !> Delassus block (nn, nt, tt, nm, tm, mm).
        real(wp), intent(in) :: w(6)
        !> Relative velocity (u_n, u_t, w_r).
        real(wp), intent(in) :: u(3)
        !> Friction coefficient and rolling length [m].
        real(wp), intent(in) :: mu, e
        !> Reaction (r_n, r_t, M).
        real(wp), intent(in) :: r(3)
        real(wp) :: sc(rolling_n_scaling), rp(3), up(3), tau(3), q(3)
        integer :: pcase
        res = 0.0_wp
        call rolling_scaling(w, mu, e, sc)
        if (sc(1) <= 0.0_wp) return
        rp = r*sc(1:3)
        up = u*sc(4:6)
        tau(1) = rp(1) - (up(1) + sc(10)*abs(up(2)) + sc(11)*abs(up(3)))
        tau(2:3) = rp(2:3) - up(2:3)
        call rolling_projection(tau(1), tau(2), tau(3), sc(10), sc(11), q(1), q(2), q(3), pcase)
        res = norm2(rp - q)
    end function rolling_residual
end module dem_bipotential
