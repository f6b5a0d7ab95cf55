!> The Arlequin coupling rows as bilateral velocity constraints inside the NLGS contact solve
!> (doc/theory.md section 6.7; used by coupling_arlequin).
!>
!> Unknowns of a coupled step: the contact impulses r and the multipliers lambda (one per
!> row of C). With G selecting the coupled particle DOFs, the end-of-step constraint is
!>   rho = G v - C v_c + e/h = 0,
!>   v   = v_free + M^-1 H r + h gamma M^-1 G^T lambda / t        (particles, per unit thickness t)
!>   v_c = v_c,free - h gamma S^-1 C^T lambda                     (FE, Newmark)
!> so that, for given contact impulses, lambda solves A lambda = -(g_free + G M^-1 H r) with
!> A = h gamma (W + C S^-1 C^T), W = G M^-1 G^T / t. Here lambda is eliminated exactly: this
!> type keeps rho = 0 at every stage of the Gauss-Seidel sweep. After a contact update has
!> changed the velocities of its two bodies, rho changes only on their rows, by
!> delta = G v - target (target = G v at the last correction); then
!>   lambda += -A^-1 delta,   G v += h gamma W_row (-A^-1 delta)
!> (A^-1 is dense and precomputed: one column per touched row, O(n_rows) per row).
!> The contacts then see the condensed problem, whose local Delassus blocks are
!>   W_eff = W_k - (h gamma / t) U^T A^-1 U,   U = G M^-1 H_k,
!> (the particle mass in series with the FE's effective mass): `condense` writes them into
!> the contact set, so that each local solve is exact and the NLGS converges as for plain
!> contacts. Why not the alternatives: point Gauss-Seidel on the rows themselves converges
!> slowly, because A is dense (the FE couples every row of an element); alternating between
!> a full contact solve and a lambda solve (block Gauss-Seidel) contracts only by the ratio
!> W_eff/W_k per pass for a contact between two coupled particles, which is near 1 when the
!> FE is much heavier than the weighted particles.
!>
!> Mediator space (multipliers on the beam nodes, coupling_operator's `mediator_t`): the
!> constraint is Pi rho = 0 with forces mu = Pi^T lambda_m on the rows. Everything above holds
!> with A^-1 replaced by B = Pi^T (Pi A Pi^T)^-1 Pi (symmetric, positive semi-definite):
!> dmu = -B delta keeps Pi rho = 0 (Pi rho changes by Pi (delta + A dmu) = 0), the rows carry
!> the forces mu and the condensed blocks use B. `ainv` holds B, `lambda` holds mu.
module coupling_bilateral
    use core_kinds, only: wp
    use dem_nlgs, only: nlgs_bilateral_t
    use dem_contacts, only: contact_set_t
    implicit none
    private
    public :: coupling_rows_t

    !> Coupling rows kept satisfied by the NLGS (see the module description).
    type, extends(nlgs_bilateral_t) :: coupling_rows_t
        !> Number of rows (multipliers).
        integer :: n_rows = 0
        !> Rows per coupled point: 2 (x, y) or 3 (x, y, rotation).
        integer :: rows_per_point = 2
        !> Point (1..n_points) of each particle, 0 when the particle is not coupled (n_disks).
        integer, allocatable :: point_of(:)
        !> Particle of each row (n_rows).
        integer, allocatable :: owner(:)
        !> Particle DOF (1 = x, 2 = y, 3 = rotation) of each row (n_rows).
        integer, allocatable :: dof(:)
        !> A^-1, or B = Pi^T (Pi A Pi^T)^-1 Pi with the mediator space (n_rows, n_rows).
        real(wp), allocatable :: ainv(:, :)
        !> Velocity of each row per unit multiplier, h gamma / ((1 - alpha) m t) [m/(N s)].
        real(wp), allocatable :: response(:)
        !> h gamma / t, the factor of the condensation [s/m].
        real(wp) :: scale = 0.0_wp
        !> Multipliers of the current step, as forces on the rows (mu = Pi^T lambda_m with the
        !> mediator space) [N, N.m] (n_rows).
        real(wp), allocatable :: lambda(:)
        !> G v at which the rows held at the last correction [m/s, rad/s] (n_rows).
        real(wp), allocatable :: target(:)
        !> Work array (n_rows).
        real(wp), allocatable :: delta(:)
        !> Corrections made since `begin` (restore + updates that touched coupled bodies).
        integer :: corrections = 0
    contains
        !> Start a step: lambda = 0 and the free residual g of the rows.
        procedure :: begin
        !> See `nlgs_bilateral_t%restore`.
        procedure :: restore
        !> See `nlgs_bilateral_t%update`.
        procedure :: update
        !> Condensed Delassus blocks of the contacts that touch coupled particles.
        procedure :: condense
        !> G v: the velocities of the coupled DOFs.
        procedure :: gather
        !> See `nlgs_bilateral_t%mobility`: C = (h gamma / t) A^-1 (or B).
        procedure :: mobility
        !> See `nlgs_bilateral_t%hold`.
        procedure :: hold
    end type coupling_rows_t

contains

    !> Start a step: lambda = 0, and the rows hold when G v = G vel - g, g being their
    !> current residual (free velocities: g = G v_free - C v_c,free + e/h).
    pure subroutine begin(self, vel, g)
        !> The rows.
        class(coupling_rows_t), intent(inout) :: self
        !> Disk velocities (3, n_disks).
        real(wp), intent(in) :: vel(:, :)
        !> Residual of the rows at these velocities with lambda = 0 (n_rows) [m/s, rad/s].
        real(wp), intent(in) :: g(:)
        call self%gather(vel, self%target)
        self%target = self%target - g
        self%lambda = 0.0_wp
        self%corrections = 0
    end subroutine begin

    !> G v: velocity of each coupled DOF (n_rows).
    pure subroutine gather(self, vel, gv)
        !> The rows.
        class(coupling_rows_t), intent(in) :: self
        !> Disk velocities (3, n_disks).
        real(wp), intent(in) :: vel(:, :)
        !> Velocities of the coupled DOFs (n_rows).
        real(wp), intent(out) :: gv(:)
        integer :: r
        do r = 1, self%n_rows
            gv(r) = vel(self%dof(r), self%owner(r))
        end do
    end subroutine gather

    !> Correct the velocities after any change: delta = G v - target on every row.
    subroutine restore(self, vel)
        !> The rows.
        class(coupling_rows_t), intent(inout) :: self
        !> Disk velocities (3, n_disks).
        real(wp), intent(inout) :: vel(:, :)
        call self%gather(vel, self%delta)
        self%delta = self%delta - self%target
        call correct(self, vel)
    end subroutine restore

    !> Correct the velocities after a contact update moved bodies a and b (only their rows
    !> can have changed).
    subroutine update(self, a, b, vel)
        !> The rows.
        class(coupling_rows_t), intent(inout) :: self
        !> Bodies of the contact (a <= 0: a wall).
        integer, intent(in) :: a, b
        !> Disk velocities (3, n_disks).
        real(wp), intent(inout) :: vel(:, :)
        integer :: rows(6), n, p, k, r
        n = 0
        p = self%point_of(b)
        if (p > 0) then
            do k = 1, self%rows_per_point
                n = n + 1
                rows(n) = (p - 1)*self%rows_per_point + k
            end do
        end if
        if (a > 0) then
            p = self%point_of(a)
            if (p > 0) then
                do k = 1, self%rows_per_point
                    n = n + 1
                    rows(n) = (p - 1)*self%rows_per_point + k
                end do
            end if
        end if
        if (n == 0) return
        do k = 1, n
            r = rows(k)
            self%delta(r) = vel(self%dof(r), self%owner(r)) - self%target(r)
        end do
        call correct(self, vel, rows(1:n))
    end subroutine update

    !> dlambda = -A^-1 delta (delta given on `rows`, on every row when rows is absent),
    !> lambda += dlambda, velocities of the coupled DOFs += response dlambda; target = G v.
    subroutine correct(self, vel, rows)
        type(coupling_rows_t), intent(inout) :: self
        real(wp), intent(inout) :: vel(:, :)
        integer, intent(in), optional :: rows(:)
        real(wp) :: dl(self%n_rows)
        if (.not. present(rows)) then
            dl = -matmul(self%ainv, self%delta)
        else
            call columns_times_delta(self%n_rows, size(rows), rows, self%ainv, self%delta, dl)
        end if
        call apply_correction(self%n_rows, size(vel, 2), self%dof, self%owner, self%response, dl, self%lambda, &
                              self%target, vel)
        self%corrections = self%corrections + 1
    end subroutine correct

    !> dl = -sum_k A^-1(:, rows(k)) delta(rows(k)), in the order of rows (the hot loop of a
    !> coupled solve: explicit shapes, so that the columns are read as contiguous vectors).
    pure subroutine columns_times_delta(m, n, rows, ainv, delta, dl)
        integer, intent(in) :: m, n, rows(n)
        real(wp), intent(in) :: ainv(m, m), delta(m)
        real(wp), intent(out) :: dl(m)
        integer :: k
        real(wp) :: d
        dl = 0.0_wp
        do k = 1, n
            d = delta(rows(k))
            dl = dl - ainv(:, rows(k))*d
        end do
    end subroutine columns_times_delta

    !> lambda += dl; the velocity of each row's DOF += response dl, and target = that velocity.
    pure subroutine apply_correction(m, nd, dof, owner, response, dl, lambda, target, vel)
        integer, intent(in) :: m, nd, dof(m), owner(m)
        real(wp), intent(in) :: response(m), dl(m)
        real(wp), intent(inout) :: lambda(m), target(m), vel(3, nd)
        integer :: r
        lambda = lambda + dl
        do r = 1, m
            vel(dof(r), owner(r)) = vel(dof(r), owner(r)) + response(r)*dl(r)
            target(r) = vel(dof(r), owner(r))
        end do
    end subroutine apply_correction

    !> vel corrected as `restore` would (lambda += -A^-1 delta, delta = G vel - target), the
    !> rows' multipliers and target left as they are.
    pure subroutine hold(self, vel)
        !> The rows.
        class(coupling_rows_t), intent(in) :: self
        !> Disk velocities (3, n_disks).
        real(wp), intent(inout) :: vel(:, :)
        real(wp) :: gv(self%n_rows), dl(self%n_rows)
        integer :: r
        call self%gather(vel, gv)
        dl = -matmul(self%ainv, gv - self%target)
        do r = 1, self%n_rows
            vel(self%dof(r), self%owner(r)) = vel(self%dof(r), self%owner(r)) + self%response(r)*dl(r)
        end do
    end subroutine hold

    !> The rows' share of the disks' mobility (nlgs_bilateral_t): an impulse p followed by
    !> `restore` changes the velocities by M^-1 p - P^T D C D P p with C = (h gamma / t) A^-1
    !> (B with the mediator space), the matrix of `condense`.
    subroutine mobility(self, owner, dof, c)
        !> The rows.
        class(coupling_rows_t), intent(in) :: self
        !> Disk and DOF of each row.
        integer, allocatable, intent(out) :: owner(:), dof(:)
        !> C (n_rows, n_rows).
        real(wp), allocatable, intent(out) :: c(:, :)
        owner = self%owner(1:self%n_rows)
        dof = self%dof(1:self%n_rows)
        c = self%scale*self%ainv
    end subroutine mobility

    !> Replace the Delassus block (W_nn, W_nt, W_tt, W_nm, W_tm, W_mm) of every contact that
    !> touches a coupled particle by the condensed one W - (h gamma/t) U^T A^-1 U (module
    !> description). Call after `contacts_set_frames` (which sets W from im) and before the
    !> solve.
    pure subroutine condense(self, cs, im)
        !> The rows.
        class(coupling_rows_t), intent(in) :: self
        !> Contacts (frames and blocks set).
        type(contact_set_t), intent(inout) :: cs
        !> Inverse mass per DOF (3, n_disks), per unit thickness, as used by the contacts.
        real(wp), intent(in) :: im(:, :)
        ! entries of the symmetric 3x3 block in the storage order of cs%w
        integer, parameter :: ii(6) = [1, 1, 2, 1, 2, 3], jj(6) = [1, 2, 2, 3, 3, 3]
        integer :: k, a, b, n, i, j, e, rows(6)
        real(wp) :: us(6, 3), s(6), aij, wk(6), d(3)
        do k = 1, cs%n
            a = cs%i1(k)
            b = cs%i2(k)
            n = 0
            call add_body(self, im, b, 1.0_wp, cs%lever(2, k), cs%nrm(:, k), n, rows, us)
            if (a > 0) call add_body(self, im, a, -1.0_wp, cs%lever(1, k), cs%nrm(:, k), n, rows, us)
            if (n == 0) cycle
            s = 0.0_wp
            do j = 1, n
                do i = 1, n
                    aij = self%ainv(rows(i), rows(j))
                    do e = 1, 6
                        s(e) = s(e) + us(i, ii(e))*aij*us(j, jj(e))
                    end do
                end do
            end do
            ! The condensed block is positive semi-definite in exact arithmetic; keep its
            ! diagonal >= 0 and each off-diagonal entry within sqrt(W_ii W_jj) against the
            ! rounding of the difference.
            wk = cs%w(:, k) - self%scale*s
            d = max(wk([1, 3, 6]), 0.0_wp)
            wk(1) = d(1)
            wk(3) = d(2)
            wk(6) = d(3)
            wk(2) = sign(min(abs(wk(2)), sqrt(d(1)*d(2))), wk(2))
            wk(4) = sign(min(abs(wk(4)), sqrt(d(1)*d(3))), wk(4))
            wk(5) = sign(min(abs(wk(5)), sqrt(d(2)*d(3))), wk(5))
            cs%w(:, k) = wk
        end do
    end subroutine condense

    !> Rows of body c (if coupled) and the rows of U = G M^-1 H there (columns r_n, r_t, M),
    !> appended after the first n: the impulse (r_n, r_t, M) acts on c with sign s (+ on i2,
    !> - on i1) through the normal n, the tangent t = (-n_y, n_x), the lever arm and the
    !> moment (rotation).
    pure subroutine add_body(self, im, c, s, lever, nrm, n, rows, us)
        type(coupling_rows_t), intent(in) :: self
        real(wp), intent(in) :: im(:, :)
        integer, intent(in) :: c
        real(wp), intent(in) :: s, lever, nrm(2)
        integer, intent(inout) :: n, rows(:)
        real(wp), intent(inout) :: us(:, :)
        integer :: p, base
        p = self%point_of(c)
        if (p == 0) return
        base = (p - 1)*self%rows_per_point
        n = n + 1
        rows(n) = base + 1
        us(n, :) = [s*im(1, c)*nrm(1), -s*im(1, c)*nrm(2), 0.0_wp]
        n = n + 1
        rows(n) = base + 2
        us(n, :) = [s*im(2, c)*nrm(2), s*im(2, c)*nrm(1), 0.0_wp]
        if (self%rows_per_point == 3) then
            n = n + 1
            rows(n) = base + 3
            us(n, :) = [0.0_wp, im(3, c)*lever, s*im(3, c)]
        end if
    end subroutine add_body
end module coupling_bilateral
