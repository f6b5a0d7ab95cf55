!> Coarse correction of the NLGS sweeps (`[solver] method = coarse`, doc/theory.md 4.6): an
!> extension of nlgs_correction_t that scales the reactions of aggregates of consecutive
!> contacts at once, by the Galerkin solution of a small system, one unknown per aggregate.
module dem_coarse
    use core_kinds, only: wp
    use core_error, only: error_t
    use core_linalg, only: dense_spd_t
    use dem_contacts, only: contact_set_t, contacts_apply_impulse, contacts_solver_velocity
    use dem_nlgs, only: nlgs_correction_t
    implicit none
    private
    public :: coarse_correction_t

    !> The coarse correction: every `every` sweeps (nlgs_correction_t), aggregates of
    !> `aggregate` consecutive contacts of the solve.
    type, extends(nlgs_correction_t) :: coarse_correction_t
        !> Contacts per aggregate (`[solver] coarse_size`).
        integer :: aggregate = 400
    contains
        !> Scale the reactions of each aggregate (coarse_correct).
        procedure :: correct => coarse_correct
    end type coarse_correction_t

    !> Largest number of aggregates (the system is factored dense: 2000^3/3 flops, about 1 s;
    !> larger aggregates are used beyond).
    integer, parameter :: max_aggregates = 2000
    !> Tikhonov term of the coarse system, relative to its diagonal: far above the rounding of
    !> its entries (1e-16), far below their size (the value of the Anderson step's).
    real(wp), parameter :: regularisation = 1.0e-12_wp

contains

    !> Coarse correction of the reactions (doc/theory.md 4.6). The
    !> contacts of the solve, in their order (bottom-up for a packing numbered by rows), are
    !> cut into aggregates A of `self%aggregate` consecutive contacts (at most max_aggregates
    !> aggregates). Each contact with r_n > 0 and
    !> no cohesion has a pattern p: its reaction when strictly inside its cone (sticking),
    !> (r_n, 0, 0) otherwise (sliding). The correction is r <- r + a_A p on the contacts of
    !> each aggregate, with a the Galerkin solution of
    !>     sum_{k in A} p_k . u_k(a) = 0   for every A,
    !> u the shifted relative velocities the sweeps see: C a = b with
    !> C_AB = (H P_A)^T M^-1 (H P_B) (symmetric, nonzero between aggregates that share a disk;
    !> factored dense) and b_A = -sum_{k in A} p_k . u_k. At a solution of the sweeps a
    !> sticking contact has u = 0 and a sliding one u_n = 0, so b = 0 and the correction does
    !> nothing: the fixed point is that of the plain sweeps. Away from it the correction moves
    !> the weight between layers in one step, where a sweep moves it by one layer. a_A is
    !> bounded below by -1/2 (the reactions keep their sign); the next sweep projects any
    !> reaction left outside its cone.
    subroutine coarse_correct(self, cs, list, im, vel)
        !> The correction (its aggregate size).
        class(coarse_correction_t), intent(in) :: self
        !> Contacts (reactions r).
        type(contact_set_t), intent(inout) :: cs
        !> The swept contacts, in the order of the sweeps.
        integer, intent(in) :: list(:)
        !> Inverse mass per DOF (3, n_disks).
        real(wp), intent(in) :: im(:, :)
        !> Disk velocities (3, n_disks), updated.
        real(wp), intent(inout) :: vel(:, :)
        type(dense_spd_t) :: c
        type(error_t), allocatable :: error
        integer, allocatable :: start(:), inc(:), fill(:)
        real(wp), allocatable :: b(:), pat(:, :)
        real(wp) :: u(3), dmax, dr, rn, ga_imp(3), gb_imp(3)
        integer :: n, na, nd, a, k, e, f, d, ga, gb, af, m
        n = size(list)
        if (n == 0) return
        ! at most max_aggregates aggregates (the coarse system is dense)
        m = max(self%aggregate, 1, (n + max_aggregates - 1)/max_aggregates)
        na = (n + m - 1)/m
        nd = size(vel, 2)
        ! pattern of each position (the reaction it scales) and the incidence of the disks
        allocate (pat(3, n), b(na), start(nd + 1), fill(nd), inc(2*n))
        b = 0.0_wp
        start = 0
        do a = 1, n
            k = list(a)
            pat(:, a) = 0.0_wp
            rn = cs%r(1, k)
            if (cs%coh(k) <= 0.0_wp .and. rn > 0.0_wp) then
                pat(1, a) = rn
                ! a contact strictly inside its cone (sticking) scales as a whole; a sliding one
                ! by its normal reaction only
                if (abs(cs%r(2, k)) < cs%mu(k)*rn .and. &
                    (cs%erol(k) <= 0.0_wp .or. abs(cs%r(3, k)) < cs%erol(k)*rn)) pat(2:3, a) = cs%r(2:3, k)
            end if
            call contacts_solver_velocity(cs, k, vel, u)
            ga = (a - 1)/m + 1
            b(ga) = b(ga) - dot_product(pat(:, a), u)
            start(cs%i2(k) + 1) = start(cs%i2(k) + 1) + 1
            if (cs%i1(k) > 0) start(cs%i1(k) + 1) = start(cs%i1(k) + 1) + 1
        end do
        start(1) = 1
        do d = 1, nd
            start(d + 1) = start(d + 1) + start(d)
        end do
        fill = start(1:nd)
        do a = 1, n
            k = list(a)
            inc(fill(cs%i2(k))) = a
            fill(cs%i2(k)) = fill(cs%i2(k)) + 1
            if (cs%i1(k) > 0) then
                inc(fill(cs%i1(k))) = -a
                fill(cs%i1(k)) = fill(cs%i1(k)) + 1
            end if
        end do
        call c%init(na)
        do d = 1, nd
            do e = start(d), start(d + 1) - 1
                a = abs(inc(e))
                if (pat(1, a) == 0.0_wp) cycle
                ga = (a - 1)/m + 1
                ga_imp = impulse(a, inc(e) > 0)
                do f = start(d), start(d + 1) - 1
                    af = abs(inc(f))
                    if (pat(1, af) == 0.0_wp) cycle
                    gb = (af - 1)/m + 1
                    if (gb < ga) cycle
                    ! the diagonal block (ga == gb) sums both orders of a pair
                    if (ga == gb .and. af < a) cycle
                    gb_imp = impulse(af, inc(f) > 0)
                    dr = sum(ga_imp*im(:, d)*gb_imp)
                    if (ga == gb .and. af /= a) dr = 2.0_wp*dr
                    c%a(ga, gb) = c%a(ga, gb) + dr
                end do
            end do
        end do
        dmax = 0.0_wp
        do ga = 1, na
            dmax = max(dmax, c%a(ga, ga))
        end do
        if (dmax <= 0.0_wp) return
        do ga = 1, na
            if (c%a(ga, ga) <= 0.0_wp) then
                c%a(ga, ga) = dmax
                b(ga) = 0.0_wp
            end if
            c%a(ga, ga) = c%a(ga, ga)*(1.0_wp + regularisation)
        end do
        call c%factor(error)
        if (allocated(error)) return
        call c%solve(b, error)
        if (allocated(error)) return
        do a = 1, n
            if (pat(1, a) == 0.0_wp) cycle
            k = list(a)
            dr = max(b((a - 1)/m + 1), -0.5_wp)
            cs%r(:, k) = cs%r(:, k) + dr*pat(:, a)
            call contacts_apply_impulse(cs, k, im, vel, dr*pat(1, a), dr*pat(2, a), dr*pat(3, a))
        end do
    contains
        ! impulse (x, y, moment) of the pattern of position q on its body i2 (plus) or i1
        pure function impulse(q, plus) result(g)
            integer, intent(in) :: q
            logical, intent(in) :: plus
            real(wp) :: g(3)
            integer :: kk
            kk = list(q)
            g(1) = pat(1, q)*cs%nrm(1, kk) - pat(2, q)*cs%nrm(2, kk)
            g(2) = pat(1, q)*cs%nrm(2, kk) + pat(2, q)*cs%nrm(1, kk)
            if (plus) then
                g(3) = cs%lever(2, kk)*pat(2, q) + pat(3, q)
            else
                g(1:2) = -g(1:2)
                g(3) = cs%lever(1, kk)*pat(2, q) - pat(3, q)
            end if
        end function impulse
    end subroutine coarse_correct

end module dem_coarse
