!> Anderson acceleration of the NLGS sweeps (doc/theory.md 4.4): the history, the mixing
!> step with its safeguards and the skip of the drift, and the kernels it runs over the
!> contacts. Part of dem_nlgs (its module header); the interfaces are declared there.
submodule(dem_nlgs) dem_nlgs_anderson
    implicit none

contains

    !> Forget the history of the Anderson acceleration (the iterate changed outside the map).
    pure module subroutine anderson_restart(aa)
        type(anderson_t), intent(inout) :: aa
        aa%used = 0
        aa%next = 1
        aa%started = .false.
        aa%fnorm_prev = huge(1.0_wp)
        aa%x_valid = .false.
        aa%mixed = .false.
    end subroutine anderson_restart

    !> Size the history and the scaling D = sqrt(diag W) of the Anderson acceleration.
    module subroutine anderson_init(aa, depth, cs, list)
        type(anderson_t), intent(inout) :: aa
        integer, intent(in) :: depth
        type(contact_set_t), intent(in) :: cs
        integer, intent(in) :: list(:)
        integer :: n, a, k
        n = 3*size(list)
        aa%depth = depth
        allocate (aa%df(n, depth), aa%dg(n, depth), aa%gram(depth, depth))
        allocate (aa%x(n), aa%fprev(n), aa%gprev(n), aa%gplain(n), aa%d(n), aa%dinv(n))
        allocate (aa%part(max(2*depth, 4), (size(list) + dot_chunk - 1)/dot_chunk), aa%dgnorm(depth))
        do a = 1, size(list)
            k = list(a)
            aa%d(3*a - 2) = sqrt(cs%w(1, k))
            aa%d(3*a - 1) = sqrt(max(cs%w(3, k), 0.0_wp))
            ! no moment: the third component stays 0
            aa%d(3*a) = merge(sqrt(max(cs%w(6, k), 0.0_wp)), 0.0_wp, cs%erol(k) > 0.0_wp)
        end do
        ! (no division by zero even where a vectorised merge evaluates both branches)
        aa%dinv = merge(1.0_wp/max(aa%d, tiny(1.0_wp)), 0.0_wp, aa%d > 0.0_wp)
    end subroutine anderson_init

    !> Scaled shifted reactions x = D (r_n + r_cohe h, r_t, M) of the contacts of the solve
    !> (on the OpenMP threads when `parallel`).
    module subroutine gather(cs, list, d, x, parallel)
        type(contact_set_t), intent(in) :: cs
        integer, intent(in) :: list(:)
        real(wp), intent(in) :: d(:)
        real(wp), intent(out) :: x(:)
        logical, intent(in) :: parallel
        integer :: a
        if (parallel) then
            !$omp parallel do schedule(static)
            do a = 1, size(list)
                call one(a)
            end do
            !$omp end parallel do
        else
            do a = 1, size(list)
                call one(a)
            end do
        end if
    contains
        subroutine one(a)
            integer, intent(in) :: a
            integer :: k
            k = list(a)
            x(3*a - 2) = d(3*a - 2)*(cs%r(1, k) + cs%coh(k))
            x(3*a - 1) = d(3*a - 1)*cs%r(2, k)
            x(3*a) = d(3*a)*cs%r(3, k)
        end subroutine one
    end subroutine gather

    !> One Anderson step after the map's sweeps: with x the reactions before them and g after,
    !> f = g - x; the new iterate is g - dG gamma, gamma minimising |f - dF gamma| over the
    !> history, projected on the cones, and the velocities are recomputed from it. When |f|
    !> rose since the last step, or the extrapolation would exceed anderson_max_step |g|, the
    !> history is cleared and g is kept (plain NLGS step). Before that, a drift (f the same as
    !> at the last step, not contracting) is skipped: the iterate jumps to g + t f, where the
    !> first reaction of the drift meets a face of its cone (drift_length), and the history is
    !> cleared.
    !> Three passes over the contacts: g, f, their differences, |f| and |g| (pass_residual); the
    !> new row of the Gram matrix and the right-hand side (pass_products); the mixed,
    !> projected iterate, kept in x for the next step (pass_mix). The sums are taken by
    !> fixed chunks of contacts, in parallel, then over the chunks in order: the same result
    !> for any number of threads. f and g of the step are kept in fprev and gprev. With
    !> `others` (a block with members) vel holds impulses of contacts outside the list: the
    !> velocities are rebuilt by removing the swept contacts' impulses, not from vfree.
    !> The fallback: when the last step mixed and the residual of the map from the mixed iterate
    !> is larger than anderson_fallback times that of the map before it, the mixed iterate was
    !> worse than the plain one:
    !> the reactions go back to that map's output g (kept in gplain), the velocities are
    !> rebuilt from them and the history is cleared. With `judge_only` (after the last sweep
    !> of a solve) only this judgement is made, nothing is mixed: the solve never ends on an
    !> iterate that no sweep judged.
    module subroutine anderson_mix(aa, cs, list, im, vfree, vel, split, bilateral, others, judge_only)
        type(anderson_t), intent(inout) :: aa
        type(contact_set_t), intent(inout) :: cs
        integer, intent(in) :: list(:)
        real(wp), intent(in) :: im(:, :), vfree(:, :)
        real(wp), intent(inout) :: vel(:, :)
        type(nlgs_split_t), intent(in) :: split
        class(nlgs_bilateral_t), intent(inout), optional :: bilateral
        logical, intent(in) :: others
        logical, intent(in) :: judge_only
        logical :: fall_back
        real(wp) :: gamma(aa%depth), rhs(aa%depth), fnorm, gnorm, fnorm_before, dfnorm2, drift
        integer :: slot, m, nc, c, j
        nc = size(aa%part, 2)
        slot = aa%next
        call pass_residual(aa%started)
        fnorm = sqrt(sum(aa%part(1, :)))
        gnorm = sqrt(sum(aa%part(2, :)))
        fnorm_before = aa%fnorm_prev
        dfnorm2 = huge(1.0_wp)
        if (aa%started) then
            aa%dgnorm(slot) = sqrt(sum(aa%part(3, :)))
            dfnorm2 = sum(aa%part(4, :))
        end if
        drift = 0.0_wp
        fall_back = .false.
        ! (divided, not multiplied: fnorm_prev is huge before the first map; a NaN falls back)
        if (aa%mixed) fall_back = .not. fnorm/anderson_fallback <= aa%fnorm_prev
        if (fall_back) then
            ! the mixed iterate was worse than the plain one (its map's residual rose): back to
            ! the plain output of the map before it, the history cleared (doc/theory.md 4.4).
            ! Keeping G(mixed) instead, as for a plain map whose residual rose, let a wild
            ! extrapolation through: the sweeps take a light disk under a heavy one back into
            ! line only at 1 - m_light/m_heavy per sweep (a stack at 5e5, doc/theory.md 4.4)
            aa%gprev = aa%gplain
            call rebuild(0)
            aa%used = 0
            aa%next = 1
            aa%started = .false.
            aa%fnorm_prev = aa%fnorm_plain
            aa%mixed = .false.
            return
        end if
        aa%mixed = .false.
        if (judge_only) then
            aa%x = aa%gprev
            return
        end if
        if (ieee_is_finite(fnorm)) drift = drift_length()
        if (drift > 0.0_wp) then
            ! the sweeps drift: no mixing of the history can follow them (there is no fixed
            ! point along the drift); skip the drift and restart the history from there
            aa%used = 0
            aa%next = 1
            aa%fnorm_prev = fnorm
            call rebuild(0)
            return
        end if
        if ((aa%started .and. fnorm > aa%fnorm_prev) .or. .not. ieee_is_finite(fnorm)) then
            ! safeguard: the residual rose (or overflowed), restart from the plain sweep's result
            aa%used = 0
            aa%next = 1
            aa%fnorm_prev = fnorm
            aa%x = aa%gprev
            return
        end if
        if (aa%started) then
            aa%used = min(aa%used + 1, aa%depth)
            aa%next = mod(slot, aa%depth) + 1
        end if
        aa%started = .true.
        aa%fnorm_prev = fnorm
        m = aa%used
        if (m == 0) then
            aa%x = aa%gprev
            return
        end if
        call pass_products(m)
        do j = 1, m
            aa%gram(slot, j) = 0.0_wp
            rhs(j) = 0.0_wp
            do c = 1, nc
                aa%gram(slot, j) = aa%gram(slot, j) + aa%part(j, c)
                rhs(j) = rhs(j) + aa%part(m + j, c)
            end do
            aa%gram(j, slot) = aa%gram(slot, j)
        end do
        call solve_small(aa%gram(1:m, 1:m), rhs(1:m), gamma(1:m))
        if (sum(abs(gamma(1:m))*aa%dgnorm(1:m)) > anderson_max_step*gnorm) then
            ! safeguard: an extrapolation larger than anderson_max_step |g|; restart from the
            ! plain sweeps' result, as when the residual rose (the velocities are those of g)
            aa%used = 0
            aa%next = 1
            aa%x = aa%gprev
            return
        end if
        ! the plain output, to fall back to if the next map finds the mixed iterate worse
        aa%gplain = aa%gprev
        aa%fnorm_plain = fnorm
        aa%mixed = .true.
        call rebuild(m)
    contains
        ! the iterate x = g - dG gamma(1:m) (+ drift f), projected on the cones, and the
        ! velocities recomputed from it
        subroutine rebuild(m)
            integer, intent(in) :: m
            integer :: j, c
            if (present(bilateral) .or. others) then
                ! the velocities without the swept contacts' impulses, with the multipliers'
                ! share as it stands (vfree + that share: the sweeps keep vel = vfree + M^-1 H r
                ! + share)
                do j = 1, size(list)
                    c = list(j)
                    call contacts_apply_impulse(cs, c, im, vel, -cs%r(1, c), -cs%r(2, c), -cs%r(3, c))
                end do
            else
                vel = vfree
            end if
            if (split%nb == 1) then
                ! one pass: each contact's impulse applied where its reaction is set, in the
                ! order of split_apply for one block
                call pass_mix(m, .true.)
            else
                call pass_mix(m, .false.)
                call split_apply(cs, split, im, vel)
            end if
            ! the multipliers of the mixed reactions: the constraints hold again (exactly, they
            ! are linear in the velocities)
            if (present(bilateral)) call bilateral%restore(vel)
        end subroutine rebuild

        ! The drift of the sweeps, when the map moves the iterate by the same f again and again
        ! without contracting (1 <= |f| / |f_prev| <= drift_high, 1 - cos(f, f_prev) below
        ! drift_cosine): the number t of further maps after which the first contact of the drift
        ! reaches a face of its cone (its status changes there), so that g + t f skips them.
        ! 0 when there is no drift, no contact reaches a face, t < drift_min, or t |f| >
        ! anderson_max_step |g|.
        real(wp) function drift_length() result(t)
            real(wp) :: cosine, rho
            integer :: c
            t = 0.0_wp
            if (dfnorm2 == huge(1.0_wp) .or. fnorm <= 0.0_wp .or. fnorm_before <= 0.0_wp) return
            rho = fnorm/fnorm_before
            if (rho < 1.0_wp .or. rho > drift_high) return
            cosine = (fnorm**2 + fnorm_before**2 - dfnorm2)/(2.0_wp*fnorm*fnorm_before)
            if (cosine < 1.0_wp - drift_cosine) return
            if (split%nb > 1) then
                !$omp parallel do schedule(static)
                do c = 1, nc
                    call bounds_chunk(c)
                end do
                !$omp end parallel do
            else
                do c = 1, nc
                    call bounds_chunk(c)
                end do
            end if
            t = minval(aa%part(4, 1:nc))
            if (t < drift_min .or. t*fnorm > anderson_max_step*gnorm) t = 0.0_wp
        end function drift_length

        ! per chunk, in aa%part(4, c): the least t > 0 at which a reaction p + t dp of the
        ! chunk (p = g / D, dp = f / D) leaves a face of its cone it is not on
        subroutine bounds_chunk(c)
            integer, intent(in) :: c
            real(wp) :: p(3), dp(3), t, scale
            integer :: a, k, i
            t = huge(1.0_wp)
            do a = (c - 1)*dot_chunk + 1, min(c*dot_chunk, size(list))
                k = list(a)
                i = 3*a - 3
                p = aa%gprev(i + 1:i + 3)*aa%dinv(i + 1:i + 3)
                dp = aa%fprev(i + 1:i + 3)*aa%dinv(i + 1:i + 3)
                scale = drift_slack*(abs(p(1)) + abs(p(2)) + abs(p(3)))
                t = min(t, time_to_face(p(1), dp(1), scale), &
                        time_to_face(cs%mu(k)*p(1) - p(2), cs%mu(k)*dp(1) - dp(2), scale), &
                        time_to_face(cs%mu(k)*p(1) + p(2), cs%mu(k)*dp(1) + dp(2), scale))
                if (cs%erol(k) > 0.0_wp) &
                    t = min(t, time_to_face(cs%erol(k)*p(1) - p(3), cs%erol(k)*dp(1) - dp(3), scale), &
                            time_to_face(cs%erol(k)*p(1) + p(3), cs%erol(k)*dp(1) + dp(3), scale))
            end do
            aa%part(4, c) = t
        end subroutine bounds_chunk

        ! g = D (r_n + r_cohe h, r_t, M), f = g - x, |f|^2 and |g|^2 per chunk in aa%part(1:2, :);
        ! with `history`, their differences with the previous ones in column slot, and |dG|^2
        ! of that column in aa%part(3, :). Like the two
        ! passes below, on the threads only when the sweeps are split; otherwise no parallel
        ! region is opened at all: even with `if (.false.)` or one thread, libgomp ends a
        ! region with a futex system call (100 per step of the 200-disk deposit, 5 % of its time)
        subroutine pass_residual(history)
            logical, intent(in) :: history
            integer :: c
            if (split%nb > 1) then
                !$omp parallel do schedule(static)
                do c = 1, nc
                    call residual_chunk(c, history)
                end do
                !$omp end parallel do
            else
                do c = 1, nc
                    call residual_chunk(c, history)
                end do
            end if
        end subroutine pass_residual

        subroutine residual_chunk(c, history)
            integer, intent(in) :: c
            logical, intent(in) :: history
            real(wp) :: g(3*dot_chunk), f(3*dot_chunk)
            integer :: a, k, lo, hi, n
            lo = 3*(c - 1)*dot_chunk + 1
            hi = 3*min(c*dot_chunk, size(list))
            n = hi - lo + 1
            do a = (c - 1)*dot_chunk + 1, min(c*dot_chunk, size(list))
                k = list(a)
                g(3*a - 2 - lo + 1) = cs%r(1, k) + cs%coh(k)
                g(3*a - 1 - lo + 1) = cs%r(2, k)
                g(3*a - lo + 1) = cs%r(3, k)
            end do
            g(1:n) = aa%d(lo:hi)*g(1:n)
            f(1:n) = g(1:n) - aa%x(lo:hi)
            if (history) then
                aa%df(lo:hi, slot) = f(1:n) - aa%fprev(lo:hi)
                aa%dg(lo:hi, slot) = g(1:n) - aa%gprev(lo:hi)
            end if
            aa%fprev(lo:hi) = f(1:n)
            aa%gprev(lo:hi) = g(1:n)
            aa%part(1, c) = dot(f(1:n), f(1:n))
            aa%part(2, c) = dot(g(1:n), g(1:n))
            if (history) then
                aa%part(3, c) = dot(aa%dg(lo:hi, slot), aa%dg(lo:hi, slot))
                aa%part(4, c) = dot(aa%df(lo:hi, slot), aa%df(lo:hi, slot))
            end if
        end subroutine residual_chunk

        ! per chunk: df_slot . df_j in aa%part(j, :), df_j . f in aa%part(m + j, :), j = 1..m
        ! (a chunk's columns stay in cache while they are read again)
        subroutine pass_products(m)
            integer, intent(in) :: m
            integer :: c
            if (split%nb > 1) then
                !$omp parallel do schedule(static)
                do c = 1, nc
                    call products_chunk(c, m)
                end do
                !$omp end parallel do
            else
                do c = 1, nc
                    call products_chunk(c, m)
                end do
            end if
        end subroutine pass_products

        subroutine products_chunk(c, m)
            integer, intent(in) :: c, m
            integer :: j, lo, hi
            lo = 3*(c - 1)*dot_chunk + 1
            hi = 3*min(c*dot_chunk, size(list))
            do j = 1, m
                aa%part(j, c) = dot(aa%df(lo:hi, slot), aa%df(lo:hi, j))
                aa%part(m + j, c) = dot(aa%df(lo:hi, j), aa%fprev(lo:hi))
            end do
        end subroutine products_chunk

        ! x = g - dG gamma, back to reactions on the cones, and x = D r of the result; with
        ! `apply_now` (the serial path), vel += M^-1 H r of each contact too
        subroutine pass_mix(m, apply_now)
            integer, intent(in) :: m
            logical, intent(in) :: apply_now
            integer :: c
            if (.not. apply_now) then
                !$omp parallel do schedule(static)
                do c = 1, nc
                    call mix_chunk(c, m, apply_now)
                end do
                !$omp end parallel do
            else
                do c = 1, nc
                    call mix_chunk(c, m, apply_now)
                end do
            end if
        end subroutine pass_mix

        subroutine mix_chunk(c, m, apply_now)
            integer, intent(in) :: c, m
            logical, intent(in) :: apply_now
            integer :: j, lo, hi
            lo = 3*(c - 1)*dot_chunk + 1
            hi = 3*min(c*dot_chunk, size(list))
            aa%x(lo:hi) = aa%gprev(lo:hi)
            do j = 1, m
                aa%x(lo:hi) = aa%x(lo:hi) - gamma(j)*aa%dg(lo:hi, j)
            end do
            if (drift > 0.0_wp) aa%x(lo:hi) = aa%x(lo:hi) + drift*aa%fprev(lo:hi)
            call project_contacts(cs%n, cs%i1, cs%i2, cs%nrm, cs%lever, cs%erol, cs%mu, cs%coh, cs%r, size(vel, 2), &
                                  im, vel, size(list), list, (c - 1)*dot_chunk + 1, min(c*dot_chunk, size(list)), &
                                  aa%x, aa%d, aa%dinv, apply_now)
        end subroutine mix_chunk
    end subroutine anderson_mix

    !> The mixed iterate of the contacts list(first:last) back to reactions on their cones:
    !> r = P_K(x / D), x = D r, on the arrays of the contact set (explicit shapes, as
    !> sweep_contacts); with apply_now, vel += M^-1 H r of each contact too
    !> (contacts_apply_impulse, written out).
    subroutine project_contacts(n, i1s, i2s, nrm, lever, erol, mu, coh, rc, nd, im, vel, nl, list, first, last, x, d, &
                                dinv, apply_now)
        integer, intent(in) :: n, nd, nl, first, last
        integer, intent(in) :: i1s(n), i2s(n), list(nl)
        real(wp), intent(in) :: nrm(2, n), lever(2, n), erol(n), mu(n), coh(n), im(3, nd), d(3*nl), dinv(3*nl)
        real(wp), intent(inout) :: rc(3, n), vel(3, nd), x(3*nl)
        logical, intent(in) :: apply_now
        real(wp) :: t(3), p(3), px, py
        integer :: a, k, i, i1, i2, pcase
        do a = first, last
            k = list(a)
            i = 3*a - 3
            t = x(i + 1:i + 3)*dinv(i + 1:i + 3)
            if (erol(k) > 0.0_wp) then
                call rolling_projection(t(1), t(2), t(3), mu(k), erol(k), p(1), p(2), p(3), pcase)
            else
                call coulomb_projection(t(1), t(2), mu(k), p(1), p(2), pcase)
                p(3) = 0.0_wp
            end if
            rc(1, k) = p(1) - coh(k)
            rc(2:3, k) = p(2:3)
            x(i + 1:i + 3) = d(i + 1:i + 3)*p
            if (.not. apply_now) cycle
            i1 = i1s(k)
            i2 = i2s(k)
            px = rc(1, k)*nrm(1, k) - rc(2, k)*nrm(2, k)
            py = rc(1, k)*nrm(2, k) + rc(2, k)*nrm(1, k)
            vel(1, i2) = vel(1, i2) + im(1, i2)*px
            vel(2, i2) = vel(2, i2) + im(2, i2)*py
            vel(3, i2) = vel(3, i2) + im(3, i2)*(lever(2, k)*rc(2, k) + rc(3, k))
            if (i1 > 0) then
                vel(1, i1) = vel(1, i1) - im(1, i1)*px
                vel(2, i1) = vel(2, i1) - im(2, i1)*py
                vel(3, i1) = vel(3, i1) + im(3, i1)*(lever(1, k)*rc(2, k) - rc(3, k))
            end if
        end do
    end subroutine project_contacts

    !> vel += M^-1 H r over the contacts of the solve, with the domain split: the blocks in
    !> parallel, then the interface (serial order for one block).
    subroutine split_apply(cs, split, im, vel)
        type(contact_set_t), intent(in) :: cs
        type(nlgs_split_t), intent(in) :: split
        real(wp), intent(in) :: im(:, :)
        real(wp), intent(inout) :: vel(:, :)
        integer :: b, j, k
        if (split%nb == 1) then
            do j = 1, size(split%order)
                k = split%order(j)
                call contacts_apply_impulse(cs, k, im, vel, cs%r(1, k), cs%r(2, k), cs%r(3, k))
            end do
            return
        end if
        !$omp parallel do schedule(static, 1) num_threads(split%nb) private(j, k)
        do b = 1, split%nb
            do j = split%start(b), split%start(b + 1) - 1
                k = split%order(j)
                call contacts_apply_impulse(cs, k, im, vel, cs%r(1, k), cs%r(2, k), cs%r(3, k))
            end do
        end do
        !$omp end parallel do
        do j = split%start(split%nb + 1), size(split%order)
            k = split%order(j)
            call contacts_apply_impulse(cs, k, im, vel, cs%r(1, k), cs%r(2, k), cs%r(3, k))
        end do
    end subroutine split_apply

    !> Solve the small symmetric system (a + lambda I) x = b (Cholesky, core_linalg), with
    !> lambda = anderson_regularisation trace(a): the differences of the history may be nearly
    !> dependent. x = 0 (a plain sweep) if the regularised system is still not positive definite.
    subroutine solve_small(a, b, x)
        real(wp), intent(in) :: a(:, :), b(:)
        real(wp), intent(out), contiguous :: x(:)
        type(dense_spd_t) :: g
        type(error_t), allocatable :: error
        real(wp) :: lambda
        integer :: i
        lambda = anderson_regularisation*sum([(a(i, i), i=1, size(b))])
        call g%init(size(b))
        g%a = a
        do i = 1, size(b)
            g%a(i, i) = g%a(i, i) + lambda
        end do
        call g%factor(error)
        x = b
        if (.not. allocated(error)) call g%solve(x, error)
        if (allocated(error)) x = 0.0_wp
        if (.not. all(ieee_is_finite(x))) x = 0.0_wp
    end subroutine solve_small

    !> Steps t > 0 until v + t dv = 0, for a constraint v >= 0 that holds with more than
    !> `slack` and decreases (dv < 0); huge otherwise.
    pure real(wp) function time_to_face(v, dv, slack) result(t)
        real(wp), intent(in) :: v, dv, slack
        t = huge(1.0_wp)
        if (dv < 0.0_wp .and. v > slack) t = v/(-dv)
    end function time_to_face

end submodule dem_nlgs_anderson
