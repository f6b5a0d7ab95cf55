!> The local contact problem of one step, u = W r + q over the active contacts, assembled
!> explicitly for export (FCLIB's 'local' problem, doc/theory.md, "Siconos error").
!>
!> Unknowns per contact, in list order: (r_n, r_t) when no active contact has a moment length
!> (dim = 2), else (r_n, r_t, M) for every contact (dim = 3; M = 0 rows of contacts without
!> moment have their W rows and columns but their cone holds M = 0). r is the shifted
!> reaction (r_n + r_cohe h, r_t, M), so that the cone is the plain one; q is the free term
!> in that unknown: q = H^T v_free + shift - W (r_cohe h, 0, 0). W = H^T M^-1 H is stored in
!> compressed sparse columns, 0-based (FCLIB's nz = -1), rows sorted within each column.
!>
!> With bilateral constraints kept by the sweeps (the Arlequin coupling rows,
!> `nlgs_bilateral_t`), the problem is the condensed one the sweeps solve: an impulse moves the
!> disks by M^-1 - P^T D C D P (`nlgs_bilateral_t%mobility`), so W = H^T (M^-1 - P^T D C D P) H,
!> dense among the contacts that touch a constrained disk; v_free is then the velocity at zero
!> contact impulses with the constraints held, and u comes from the velocities of the solve.
module dem_local_problem
    use core_kinds, only: wp
    use dem_contacts, only: contact_set_t, contacts_directions
    use dem_nlgs, only: nlgs_bilateral_t
    use dem_bipotential, only: coulomb_projection, rolling_projection
    implicit none
    private
    public :: local_problem_t, local_problem_build, local_problem_siconos_error

    !> The assembled local problem.
    type :: local_problem_t
        !> Components per contact (2 or 3) and number of contacts.
        integer :: dim = 2, n = 0
        !> W in compressed sparse columns (0-based): column starts (dim n + 1) and row indices
        !> (nnz).
        integer, allocatable :: colptr(:), rowind(:)
        !> W's nonzero values, in the order of rowind (nnz).
        real(wp), allocatable :: values(:)
        !> Free term (dim n), friction coefficients, cohesive impulses r_cohe h and moment
        !> lengths (n).
        real(wp), allocatable :: q(:), mu(:), cohesion(:), rolling(:)
        !> The reactions of the contact set (shifted, dim n) and u = W r + q computed from the
        !> velocities vfree + M^-1 H r (dim n).
        real(wp), allocatable :: r(:), u(:)
        !> Bodies of each contact (i1: disk or -wall, i2: disk) and index in the contact set.
        integer, allocatable :: i1(:), i2(:), index(:)
    end type local_problem_t

contains

    !> Siconos error of the solution (r, u) of the problem as exported, every contact with its
    !> dim components (doc/theory.md 4.5):
    !>     sqrt(sum_a |r_a - P_K(r_a - u_hat_a)|^2) / max(|q|, |r|, |u|),
    !> u_hat = (u_n + mu |u_t| + e |w_r|, u_t, w_r), K the cone |r_t| <= mu r_n, |M| <= e r_n
    !> (for e = 0 the cone holds M = 0: the third residual component is M itself). The sums
    !> |q|^2 and |u|^2 take every component, the rotation w_r of a contact without a moment
    !> too, so that this is the error of the file's problem; the run's own error
    !> (nlgs_siconos_error) leaves the third component of such contacts out of |q| and |u|.
    !> 0 without contacts.
    pure real(wp) function local_problem_siconos_error(lp) result(err)
        !> The problem and its solution.
        type(local_problem_t), intent(in) :: lp
        real(wp) :: r(3), u(3), t(3), p(3), num, nq, nr, nu, den
        integer :: j, d, lo, pcase
        d = lp%dim
        num = 0.0_wp
        nq = 0.0_wp
        nr = 0.0_wp
        nu = 0.0_wp
        do j = 1, lp%n
            lo = d*(j - 1)
            r = 0.0_wp
            u = 0.0_wp
            r(1:d) = lp%r(lo + 1:lo + d)
            u(1:d) = lp%u(lo + 1:lo + d)
            if (lp%rolling(j) > 0.0_wp) then
                t = r - [u(1) + lp%mu(j)*abs(u(2)) + lp%rolling(j)*abs(u(3)), u(2), u(3)]
                call rolling_projection(t(1), t(2), t(3), lp%mu(j), lp%rolling(j), p(1), p(2), p(3), pcase)
            else
                t = [r(1) - (u(1) + lp%mu(j)*abs(u(2))), r(2) - u(2), 0.0_wp]
                call coulomb_projection(t(1), t(2), lp%mu(j), p(1), p(2), pcase)
                p(3) = 0.0_wp
            end if
            num = num + sum((r - p)**2)
            nq = nq + sum(lp%q(lo + 1:lo + d)**2)
            nr = nr + sum(r**2)
            nu = nu + sum(u**2)
        end do
        den = sqrt(max(nq, nr, nu))
        err = 0.0_wp
        if (den > 0.0_wp) err = sqrt(num)/den
    end function local_problem_siconos_error

    !> Assemble the local problem of the active contacts of cs.
    subroutine local_problem_build(cs, im, vfree, lp, bilateral, vel)
        !> Contacts after the solve (frames, laws, activity, reactions).
        type(contact_set_t), intent(in) :: cs
        !> Inverse mass per DOF (3, n_disks).
        real(wp), intent(in) :: im(:, :)
        !> Free velocities of the step (3, n_disks); with `bilateral`, those at zero contact
        !> impulses with the constraints held.
        real(wp), intent(in) :: vfree(:, :)
        !> The problem.
        type(local_problem_t), intent(out) :: lp
        !> Bilateral constraints kept by the solve (their share of the mobility enters W).
        class(nlgs_bilateral_t), intent(in), optional :: bilateral
        !> Velocities at the end of the solve (3, n_disks), for u; needed with `bilateral`
        !> (otherwise u comes from vfree + M^-1 H r).
        real(wp), intent(in), optional :: vel(:, :)
        integer, allocatable :: pos(:), adj_start(:), adj(:), rows(:), owner(:), dof(:), tpos(:), trow(:)
        real(wp), allocatable :: vq(:, :), vr(:, :), vals(:), cmat(:, :), um(:, :), cu(:, :)
        real(wp) :: ga(3, 3), gb(3, 3), s
        integer :: nd, m, d, k, a, b, c, e, j, side, body, nnz, nrow, col, nt, i
        logical :: condensed
        nd = size(im, 2)
        m = count(cs%active(1:cs%n))
        lp%n = m
        lp%dim = 2
        if (any(cs%active(1:cs%n) .and. cs%erol(1:cs%n) > 0.0_wp)) lp%dim = 3
        d = lp%dim
        allocate (lp%i1(m), lp%i2(m), lp%index(m), lp%mu(m), lp%cohesion(m), lp%rolling(m))
        allocate (pos(cs%n), source=0)
        j = 0
        do k = 1, cs%n
            if (.not. cs%active(k)) cycle
            j = j + 1
            pos(k) = j
            lp%index(j) = k
            lp%i1(j) = cs%i1(k)
            lp%i2(j) = cs%i2(k)
            lp%mu(j) = cs%mu(k)
            lp%cohesion(j) = cs%coh(k)
            lp%rolling(j) = cs%erol(k)
        end do
        ! contacts of each disk (CSR)
        allocate (adj_start(nd + 1), source=0)
        do j = 1, m
            if (lp%i1(j) > 0) adj_start(lp%i1(j) + 1) = adj_start(lp%i1(j) + 1) + 1
            adj_start(lp%i2(j) + 1) = adj_start(lp%i2(j) + 1) + 1
        end do
        adj_start(1) = 1
        do body = 1, nd
            adj_start(body + 1) = adj_start(body + 1) + adj_start(body)
        end do
        allocate (adj(adj_start(nd + 1) - 1), rows(nd))
        rows(1:nd) = adj_start(1:nd)
        do j = 1, m
            if (lp%i1(j) > 0) then
                adj(rows(lp%i1(j))) = j
                rows(lp%i1(j)) = rows(lp%i1(j)) + 1
            end if
            adj(rows(lp%i2(j))) = j
            rows(lp%i2(j)) = rows(lp%i2(j)) + 1
        end do
        condensed = present(bilateral)
        if (condensed) call constraint_share()
        ! W column by column: the block of contact b with itself is cs%w; with another
        ! contact a it is the term of the one body they share. Condensed: the block of b with
        ! itself is summed over its bodies as the others (cs%w may hold a condensed block
        ! already), and the constraints' share -U^T C U is added on the contacts that touch
        ! a constrained disk.
        allocate (lp%colptr(d*m + 1))
        allocate (lp%rowind(d*d*m*8), lp%values(d*d*m*8))
        deallocate (rows)
        allocate (rows(64), vals(64))
        nnz = 0
        lp%colptr(1) = 0
        do b = 1, m
            k = lp%index(b)
            do c = 1, d
                nrow = 0
                if (.not. condensed) call add_self(k, c)
                do side = 1, 2
                    body = merge(lp%i1(b), lp%i2(b), side == 1)
                    if (body <= 0) cycle
                    gb = contacts_directions(cs, lp%index(b), side)
                    do e = adj_start(body), adj_start(body + 1) - 1
                        a = adj(e)
                        if (a == b .and. .not. condensed) cycle
                        ga = contacts_directions(cs, lp%index(a), merge(2, 1, body == cs%i2(lp%index(a))))
                        do j = 1, d
                            s = sum(ga(:, j)*im(:, body)*gb(:, c))
                            call push(d*(a - 1) + j - 1, s)
                        end do
                    end do
                end do
                col = d*(b - 1) + c
                if (condensed) then
                    if (tpos(col) > 0) then
                        do i = 1, nt
                            call push(trow(i), -dot_product(um(:, i), cu(:, tpos(col))))
                        end do
                    end if
                end if
                call sort_rows(rows(1:nrow), vals(1:nrow))
                if (condensed) call merge_rows(rows, vals, nrow)
                if (nnz + nrow > size(lp%rowind)) call grow(nnz + nrow)
                lp%rowind(nnz + 1:nnz + nrow) = rows(1:nrow)
                lp%values(nnz + 1:nnz + nrow) = vals(1:nrow)
                nnz = nnz + nrow
                lp%colptr(col + 1) = nnz
            end do
        end do
        lp%rowind = lp%rowind(1:nnz)
        lp%values = lp%values(1:nnz)
        ! q from the free velocities shifted by the cohesion, u from vfree + M^-1 H r (or the
        ! velocities of the solve). Condensed, the shift by the cohesion goes through W: the
        ! constraints respond to the cohesion impulses too.
        allocate (vq, source=vfree)
        allocate (vr, source=vfree)
        if (present(vel)) vr = vel
        do j = 1, m
            k = lp%index(j)
            if (.not. condensed) call impulse(cs, k, im, vq, [-cs%coh(k), 0.0_wp, 0.0_wp])
            if (.not. present(vel)) call impulse(cs, k, im, vr, cs%r(:, k))
        end do
        allocate (lp%q(d*m), lp%u(d*m), lp%r(d*m))
        do j = 1, m
            k = lp%index(j)
            call velocity(cs, k, vq, lp%q(d*(j - 1) + 1:d*j))
            call velocity(cs, k, vr, lp%u(d*(j - 1) + 1:d*j))
            lp%r(d*(j - 1) + 1) = cs%r(1, k) + cs%coh(k)
            lp%r(d*(j - 1) + 2) = cs%r(2, k)
            if (d == 3) lp%r(d*j) = cs%r(3, k)
        end do
        if (condensed) then
            ! q -= W (r_cohe h, 0, 0): the normal columns of the cohesive contacts
            do j = 1, m
                if (lp%cohesion(j) == 0.0_wp) cycle
                col = d*(j - 1) + 1
                do e = lp%colptr(col) + 1, lp%colptr(col + 1)
                    lp%q(lp%rowind(e) + 1) = lp%q(lp%rowind(e) + 1) - lp%values(e)*lp%cohesion(j)
                end do
            end do
        end if
    contains
        ! U = D P H on the unknowns of the contacts that touch a constrained disk (um, one
        ! column per such unknown; tpos: the column of an unknown, 0 for the others; trow:
        ! the 0-based unknown of a column) and C U (cu)
        subroutine constraint_share()
            logical, allocatable :: constrained(:), touches(:)
            integer :: r, nr
            call bilateral%mobility(owner, dof, cmat)
            nr = size(owner)
            allocate (constrained(nd), touches(m), tpos(d*m))
            constrained = .false.
            if (nr > 0) constrained(owner) = .true.
            do j = 1, m
                touches(j) = constrained(lp%i2(j))
                if (lp%i1(j) > 0) touches(j) = touches(j) .or. constrained(lp%i1(j))
            end do
            nt = d*count(touches)
            allocate (um(nr, nt), trow(nt))
            um = 0.0_wp
            tpos = 0
            i = 0
            do j = 1, m
                if (.not. touches(j)) cycle
                do c = 1, d
                    i = i + 1
                    tpos(d*(j - 1) + c) = i
                    trow(i) = d*(j - 1) + c - 1
                    do side = 1, 2
                        body = merge(lp%i1(j), lp%i2(j), side == 1)
                        if (body <= 0) cycle
                        if (.not. constrained(body)) cycle
                        gb = contacts_directions(cs, lp%index(j), side)
                        do r = 1, nr
                            if (owner(r) /= body) cycle
                            um(r, i) = um(r, i) + im(dof(r), body)*gb(dof(r), c)
                        end do
                    end do
                end do
            end do
            cu = matmul(cmat, um)
        end subroutine constraint_share

        ! the diagonal block from cs%w (sum over both bodies)
        subroutine add_self(k, c)
            integer, intent(in) :: k, c
            integer, parameter :: idx(3, 3) = reshape([1, 2, 4, 2, 3, 5, 4, 5, 6], [3, 3])
            integer :: i
            do i = 1, d
                call push(d*(pos(k) - 1) + i - 1, cs%w(idx(i, c), k))
            end do
        end subroutine add_self

        subroutine push(row, v)
            integer, intent(in) :: row
            real(wp), intent(in) :: v
            if (nrow == size(rows)) then
                rows = [rows, rows]
                vals = [vals, vals]
            end if
            nrow = nrow + 1
            rows(nrow) = row
            vals(nrow) = v
        end subroutine push

        subroutine grow(need)
            integer, intent(in) :: need
            integer, allocatable :: ti(:)
            real(wp), allocatable :: tv(:)
            allocate (ti(max(need, 2*size(lp%rowind))), tv(max(need, 2*size(lp%rowind))))
            ti(1:nnz) = lp%rowind(1:nnz)
            tv(1:nnz) = lp%values(1:nnz)
            call move_alloc(ti, lp%rowind)
            call move_alloc(tv, lp%values)
        end subroutine grow
    end subroutine local_problem_build

    !> vel += M^-1 H dr for contact k.
    pure subroutine impulse(cs, k, im, vel, dr)
        type(contact_set_t), intent(in) :: cs
        integer, intent(in) :: k
        real(wp), intent(in) :: im(:, :), dr(3)
        real(wp), intent(inout) :: vel(:, :)
        real(wp) :: g(3, 3)
        g = contacts_directions(cs, k, 2)
        vel(:, cs%i2(k)) = vel(:, cs%i2(k)) + im(:, cs%i2(k))*matmul(g, dr)
        if (cs%i1(k) <= 0) return
        g = contacts_directions(cs, k, 1)
        vel(:, cs%i1(k)) = vel(:, cs%i1(k)) + im(:, cs%i1(k))*matmul(g, dr)
    end subroutine impulse

    !> Local velocity H^T v + shift of contact k, its first size(u) components.
    pure subroutine velocity(cs, k, vel, u)
        type(contact_set_t), intent(in) :: cs
        integer, intent(in) :: k
        real(wp), intent(in) :: vel(:, :)
        real(wp), intent(out) :: u(:)
        real(wp) :: g(3, 3), w(3)
        g = contacts_directions(cs, k, 2)
        w = matmul(vel(:, cs%i2(k)), g)
        if (cs%i1(k) > 0) then
            g = contacts_directions(cs, k, 1)
            w = w + matmul(vel(:, cs%i1(k)), g)
        end if
        w(1:2) = w(1:2) + cs%shift(:, k)
        u = w(1:size(u))
    end subroutine velocity

    !> Sum the values of equal rows of the sorted (rows(1:n), vals(1:n)); n becomes the
    !> number of distinct rows.
    pure subroutine merge_rows(rows, vals, n)
        integer, intent(inout) :: rows(:), n
        real(wp), intent(inout) :: vals(:)
        integer :: i, k
        if (n == 0) return
        k = 1
        do i = 2, n
            if (rows(i) == rows(k)) then
                vals(k) = vals(k) + vals(i)
            else
                k = k + 1
                rows(k) = rows(i)
                vals(k) = vals(i)
            end if
        end do
        n = k
    end subroutine merge_rows

    !> Sort (rows, vals) by row (insertion sort: a column has a few entries).
    pure subroutine sort_rows(rows, vals)
        integer, intent(inout) :: rows(:)
        real(wp), intent(inout) :: vals(:)
        integer :: i, j, r
        real(wp) :: v
        do i = 2, size(rows)
            r = rows(i)
            v = vals(i)
            j = i - 1
            do while (j >= 1)
                if (rows(j) <= r) exit
                rows(j + 1) = rows(j)
                vals(j + 1) = vals(j)
                j = j - 1
            end do
            rows(j + 1) = r
            vals(j + 1) = v
        end do
    end subroutine sort_rows
end module dem_local_problem
