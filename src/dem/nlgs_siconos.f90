!> Siconos error of the contact problem (doc/theory.md 4.5): the final error of every
!> solve, the error the stopping test siconos_criterion_t evaluates, and |q|. Part of dem_nlgs (its
!> module header); the interfaces are declared there.
submodule(dem_nlgs) dem_nlgs_siconos
    implicit none

contains

    !> Siconos error of the current reactions (doc/theory.md, "Siconos error"), u computed in
    !> full from the free velocities: vwork = vfree + M^-1 H r (or vel itself when bilateral
    !> constraints changed the velocities: their impulses are not contacts); nq = |q|
    !> (siconos_free_norm); `held` as in siconos_ratio.
    real(wp) module function siconos_error(cs, im, vfree, vel, vwork, bilateral, nq, held) result(err)
        type(contact_set_t), intent(in) :: cs
        real(wp), intent(in) :: im(:, :), vfree(:, :), vel(:, :), nq
        real(wp), intent(inout) :: vwork(:, :)
        logical, intent(in) :: bilateral
        logical, intent(in), optional :: held(:)
        integer :: k
        if (bilateral) then
            vwork = vel
        else
            vwork = vfree
            call nlgs_apply_reactions(cs, im, vwork)
        end if
        err = siconos_ratio(cs, pack([(k, k=1, cs%n)], cs%active(1:cs%n)), vwork, nq, held)
    end function siconos_error

    !> Siconos error of the contact problem u = W r + q over the active contacts:
    !>     sqrt(sum_a |r_a - P_K(r_a - u_hat_a)|^2) / max(|q|, |r|, |u|),
    !> with r the shifted reaction (r_n + r_cohe h, r_t, M), u_hat = (u_n + mu |u_t| + e |w_r|,
    !> u_t, w_r) (e |w_r| and the third component only for a law with moments), q = u - W r
    !> the free term in the shifted unknown (H^T v_free + shift - W (r_cohe h, 0, 0)) and u
    !> the local velocities of `vel` (doc/theory.md, "Siconos error"). 0 without active
    !> contacts.
    module function nlgs_siconos_error(cs, im, vfree, vel) result(err)
        !> Contacts (reactions r).
        type(contact_set_t), intent(in) :: cs
        !> Inverse mass per DOF (3, n_disks).
        real(wp), intent(in) :: im(:, :)
        !> Free velocities (3, n_disks).
        real(wp), intent(in) :: vfree(:, :)
        !> Velocities (3, n_disks) of the reactions (vfree + M^-1 H r).
        real(wp), intent(in) :: vel(:, :)
        real(wp) :: err
        integer :: k
        err = siconos_ratio(cs, pack([(k, k=1, cs%n)], cs%active(1:cs%n)), vel, siconos_free_norm(cs, im, vfree))
    end function nlgs_siconos_error

    !> |q| over the active contacts: q = H^T vq + shift, vq the velocities of the free term in
    !> the shifted unknown (the free motion minus the cohesion impulses; with bilateral
    !> constraints, held by them: the problem is the condensed one). The square root of the
    !> sum of squares (with the max in siconos_quotient, bitwise the error computed from the
    !> squares), or norm2 where the squares overflow.
    real(wp) module function siconos_free_norm(cs, im, vfree, bilateral) result(nq)
        type(contact_set_t), intent(in) :: cs
        real(wp), intent(in) :: im(:, :), vfree(:, :)
        class(nlgs_bilateral_t), intent(in), optional :: bilateral
        real(wp), allocatable :: vq(:, :)
        real(wp) :: q(3), qmax
        integer :: k, pass
        allocate (vq, source=vfree)
        do k = 1, cs%n
            if (.not. cs%active(k)) cycle
            if (cs%coh(k) /= 0.0_wp) call contacts_apply_impulse(cs, k, im, vq, -cs%coh(k), 0.0_wp, 0.0_wp)
        end do
        if (present(bilateral)) call bilateral%hold(vq)
        ! pass 1: the sum of squares; where it overflows, pass 2 finds the largest component
        ! and pass 3 sums the squares scaled by it
        qmax = 1.0_wp
        do pass = 1, 3
            nq = 0.0_wp
            do k = 1, cs%n
                if (.not. cs%active(k)) cycle
                call contacts_solver_velocity(cs, k, vq, q)
                if (cs%erol(k) <= 0.0_wp) q(3) = 0.0_wp
                select case (pass)
                case (1)
                    nq = nq + sum(q**2)
                case (2)
                    nq = max(nq, maxval(abs(q)))
                case default
                    nq = nq + sum((q/qmax)**2)
                end select
            end do
            if (pass == 1 .and. ieee_is_finite(nq)) exit
            if (pass == 2) qmax = nq
        end do
        nq = qmax*sqrt(nq)
    end function siconos_free_norm

    !> Estimate of the round-off floor of the Siconos error of the current reactions. The local
    !> velocities u = H^T (vfree + M^-1 H r) + shift are sums whose terms can be far larger than
    !> u: under a heavy disk a light one receives two opposite impulses of the heavy one's
    !> weight, each changing its velocity by (m_heavy / m_light) g h, and they cancel. Each
    !> component of u is then known only to epsilon times the magnitudes summed into it, so
    !> the error cannot fall below epsilon times the norm of those magnitudes over its
    !> denominator max(|q|, |r|, |u|) (nq = |q|). The magnitudes: per disk |vfree| plus
    !> M^-1 times the sum of the absolute impulses of its active contacts (plus the net
    !> velocity change of bilateral constraints, if any, in vel), then per contact the
    !> absolute frame components of its two disks' magnitudes and of its shift. An estimate
    !> of the worst rounding, not a bound: a tolerance below it is out of reach (a stack at a
    !> mass ratio of 5e5 stalls at about the estimate, `test_nlgs`).
    real(wp) module function siconos_floor(cs, im, vfree, vel, nq) result(floor)
        type(contact_set_t), intent(in) :: cs
        real(wp), intent(in) :: im(:, :), vfree(:, :), vel(:, :), nq
        real(wp), allocatable :: s(:, :), vnet(:, :)
        real(wp) :: m(3), u(3), px, py, mz1, mz2, nx, ny, num, nr, nu, den
        integer :: k, a, b
        ! the velocities of the contacts alone; what vel holds beyond them is the bilateral part
        allocate (vnet, source=vfree)
        do k = 1, cs%n
            if (cs%active(k)) call contacts_apply_impulse(cs, k, im, vnet, cs%r(1, k), cs%r(2, k), cs%r(3, k))
        end do
        s = abs(vfree) + abs(vel - vnet)
        do k = 1, cs%n
            if (.not. cs%active(k)) cycle
            a = cs%i1(k)
            b = cs%i2(k)
            px = abs(cs%r(1, k)*cs%nrm(1, k)) + abs(cs%r(2, k)*cs%nrm(2, k))
            py = abs(cs%r(1, k)*cs%nrm(2, k)) + abs(cs%r(2, k)*cs%nrm(1, k))
            mz2 = abs(cs%lever(2, k)*cs%r(2, k)) + abs(cs%r(3, k))
            mz1 = abs(cs%lever(1, k)*cs%r(2, k)) + abs(cs%r(3, k))
            s(:, b) = s(:, b) + im(:, b)*[px, py, mz2]
            if (a > 0) s(:, a) = s(:, a) + im(:, a)*[px, py, mz1]
        end do
        num = 0.0_wp
        nr = 0.0_wp
        nu = 0.0_wp
        do k = 1, cs%n
            if (.not. cs%active(k)) cycle
            a = cs%i1(k)
            b = cs%i2(k)
            nx = abs(cs%nrm(1, k))
            ny = abs(cs%nrm(2, k))
            m = [nx*s(1, b) + ny*s(2, b) + abs(cs%shift(1, k)), &
                 ny*s(1, b) + nx*s(2, b) + abs(cs%lever(2, k))*s(3, b) + abs(cs%shift(2, k)), s(3, b)]
            if (a > 0) m = m + [nx*s(1, a) + ny*s(2, a), ny*s(1, a) + nx*s(2, a) + abs(cs%lever(1, k))*s(3, a), &
                                s(3, a)]
            if (cs%erol(k) <= 0.0_wp) m(3) = 0.0_wp
            num = num + sum(m**2)
            call contacts_solver_velocity(cs, k, vel, u)
            if (cs%erol(k) <= 0.0_wp) u(3) = 0.0_wp
            nr = nr + (cs%r(1, k) + cs%coh(k))**2 + cs%r(2, k)**2 + merge(cs%r(3, k)**2, 0.0_wp, cs%erol(k) > 0.0_wp)
            nu = nu + sum(u**2)
        end do
        den = max(nq, sqrt(nr), sqrt(nu))
        floor = 0.0_wp
        if (den > 0.0_wp) floor = epsilon(1.0_wp)*sqrt(num)/den
    end function siconos_floor

    !> The ratio of nlgs_siconos_error for the velocities vel, with nq = |q|
    !> (siconos_free_norm), over the active contacts act (in increasing order). With `held`
    !> (size >= cs%n), the contacts k with held(k) are measured as the bilateral constraints
    !> of a block solve (the intact bonds of dem_bonded_block): their residual is u_hat on the
    !> locked components (siconos_ratio_contacts), zero exactly when u = 0 there, whether or
    !> not the reaction lies in its cone.
    pure real(wp) module function siconos_ratio(cs, act, vel, nq, held) result(err)
        type(contact_set_t), intent(in) :: cs
        integer, intent(in) :: act(:)
        real(wp), intent(in) :: vel(:, :), nq
        logical, intent(in), optional :: held(:)
        real(wp) :: num, nr, nu, amax, c
        err = 0.0_wp
        ! (no contact arrays to pass before the first contact)
        if (size(act) == 0) return
        call ratio_pass(.false., 1.0_wp, num, nr, nu, amax)
        if (ieee_is_finite(num) .and. ieee_is_finite(nr) .and. ieee_is_finite(nu)) then
            err = siconos_quotient(num, nr, nu, nq)
            return
        end if
        ! (a second pass measures the largest component; non-finite values stay as they are)
        call ratio_pass(.true., 1.0_wp, num, nr, nu, amax)
        if (.not. (amax > 0.0_wp .and. amax <= huge(amax))) then
            err = siconos_quotient(num, nr, nu, nq)
            return
        end if
        ! Finite values whose squares overflow (reactions beyond 1e154: disks of density 1e300
        ! gave a NaN error, inf/inf). The projections on the cones are positively homogeneous:
        ! r and u scaled by the power of 2 c ~ 1/amax (exact) give the same ratio.
        c = scale(1.0_wp, -exponent(amax))
        call ratio_pass(.true., c, num, nr, nu, amax)
        err = siconos_quotient(num, nr, nu, nq*c)
    contains
        !> One pass of siconos_ratio_contacts (scaled, by c), with or without `held`.
        pure subroutine ratio_pass(scaled, c, num, nr, nu, amax)
            logical, intent(in) :: scaled
            real(wp), intent(in) :: c
            real(wp), intent(out) :: num, nr, nu, amax
            logical :: none(0)
            if (present(held)) then
                call siconos_ratio_contacts(cs%n, cs%i1, cs%i2, cs%nrm, cs%lever, cs%shift, cs%r, cs%coh, cs%erol, &
                                            cs%mu, size(vel, 2), vel, size(act), act, cs%n, held(1:cs%n), scaled, c, &
                                            num, nr, nu, amax)
            else
                call siconos_ratio_contacts(cs%n, cs%i1, cs%i2, cs%nrm, cs%lever, cs%shift, cs%r, cs%coh, cs%erol, &
                                            cs%mu, size(vel, 2), vel, size(act), act, 0, none, scaled, c, num, nr, &
                                            nu, amax)
            end if
        end subroutine ratio_pass
    end function siconos_ratio

    !> sqrt(num) / max(nq, sqrt(nr), sqrt(nu)), 0 when the denominator vanishes.
    pure real(wp) function siconos_quotient(num, nr, nu, nq) result(err)
        real(wp), intent(in) :: num, nr, nu, nq
        real(wp) :: den
        den = max(nq, sqrt(nr), sqrt(nu))
        err = 0.0_wp
        if (den > 0.0_wp) err = sqrt(num)/den
    end function siconos_quotient

    !> siconos_ratio on the arrays of the contact set (explicit shapes, as sweep_contacts; the
    !> local velocity written out as there: this runs after most sweeps of a long solve, and a
    !> shared procedure for it was not inlined, 3 % more time on the 200-disk deposit).
    pure subroutine siconos_ratio_contacts(n, i1s, i2s, nrm, lever, shift, rc, coh, erol, mu, nd, vel, na, &
                                           act, nh, held, scaled, c, num, nr, nu, amax)
        integer, intent(in) :: n, nd, na, nh
        integer, intent(in) :: i1s(n), i2s(n), act(na)
        !> Contacts held as bilateral constraints (nh = n), or none (nh = 0): for those the
        !> residual is u_hat on the locked components (the normal one, the tangential one when
        !> mu > 0, the rotation when e > 0), the natural map of the equality u = 0 there (the
        !> bilateral constraints of a block solve, whose reactions may leave their cones until
        !> the outer check releases them). A held contact whose reaction lies in its cone
        !> contributes at least as much as its term of the Siconos error, the projection on
        !> the cone being non-expansive (|r - P_K(r - u_hat)| = |P_K(r) - P_K(r - u_hat)| <=
        !> |u_hat|), and exactly as much while r - u_hat stays in the cone.
        logical, intent(in) :: held(nh)
        real(wp), intent(in) :: nrm(2, n), lever(2, n), shift(2, n), rc(3, n), coh(n), erol(n), mu(n)
        real(wp), intent(in) :: vel(3, nd)
        !> Whether r and u are scaled by c and amax measured (only after squares overflowed:
        !> the usual pass does neither).
        logical, intent(in) :: scaled
        !> Scale of r and u (1, or 1/amax of a first pass whose squares overflowed).
        real(wp), intent(in) :: c
        !> Sums of |r - P_K(r - u_hat)|^2, |r|^2 and |u|^2 of the scaled values.
        real(wp), intent(out) :: num, nr, nu
        !> Largest |component| of the scaled r and u (0 when not `scaled`).
        real(wp), intent(out) :: amax
        real(wp) :: u(3), r(3), t(3), p(3), dvx, dvy, nx, ny
        integer :: a, k, i1, i2, pcase
        num = 0.0_wp
        nr = 0.0_wp
        nu = 0.0_wp
        amax = 0.0_wp
        do a = 1, na
            k = act(a)
            i1 = i1s(k)
            i2 = i2s(k)
            dvx = vel(1, i2)
            dvy = vel(2, i2)
            u(2) = lever(2, k)*vel(3, i2) + shift(2, k)
            u(3) = vel(3, i2)
            if (i1 > 0) then
                dvx = dvx - vel(1, i1)
                dvy = dvy - vel(2, i1)
                u(2) = u(2) + lever(1, k)*vel(3, i1)
                u(3) = u(3) - vel(3, i1)
            end if
            nx = nrm(1, k)
            ny = nrm(2, k)
            u(1) = nx*dvx + ny*dvy + shift(1, k)
            u(2) = u(2) - ny*dvx + nx*dvy
            r = [rc(1, k) + coh(k), rc(2, k), rc(3, k)]
            if (scaled) then
                r = c*r
                u = c*u
                amax = max(amax, maxval(abs(r)), maxval(abs(u)))
            end if
            if (erol(k) <= 0.0_wp) then
                u(3) = 0.0_wp
                r(3) = 0.0_wp
            end if
            if (nh > 0) then
                if (held(k)) then
                    ! held: the residual is u_hat on the locked components (see `held`)
                    p = [u(1) + mu(k)*abs(u(2)) + erol(k)*abs(u(3)), u(2), u(3)]
                    if (mu(k) <= 0.0_wp) p(2) = 0.0_wp
                    num = num + sum(p**2)
                    nr = nr + sum(r**2)
                    nu = nu + sum(u**2)
                    cycle
                end if
            end if
            if (erol(k) > 0.0_wp) then
                t = r - [u(1) + mu(k)*abs(u(2)) + erol(k)*abs(u(3)), u(2), u(3)]
                call rolling_projection(t(1), t(2), t(3), mu(k), erol(k), p(1), p(2), p(3), pcase)
            else
                t = [r(1) - (u(1) + mu(k)*abs(u(2))), r(2) - u(2), 0.0_wp]
                call coulomb_projection(t(1), t(2), mu(k), p(1), p(2), pcase)
                p(3) = 0.0_wp
            end if
            num = num + sum((r - p)**2)
            nr = nr + sum(r**2)
            nu = nu + sum(u**2)
        end do
    end subroutine siconos_ratio_contacts

end submodule dem_nlgs_siconos
