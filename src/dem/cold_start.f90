!> Cold start of a contact solve (`[solver] cold_start = hydrostatic`): the hydrostatic
!> estimate of the reactions, an extension of nlgs_start_t from which dem_nlgs starts the
!> sweeps when no contact of the solve carries a reaction yet (doc/theory.md section 4.7;
!> figures in doc/performance.md, "Cold start").
module dem_cold_start
    use core_kinds, only: wp
    use dem_contacts, only: contact_set_t
    use dem_nlgs, only: nlgs_start_t
    implicit none
    private
    public :: hydrostatic_start_t

    !> The hydrostatic estimate (hydrostatic_guess).
    type, extends(nlgs_start_t) :: hydrostatic_start_t
    contains
        !> The weight carried down the contact network from the top.
        procedure :: guess => hydrostatic_guess
        !> 'hydrostatic'.
        procedure :: name => hydrostatic_name
    end type hydrostatic_start_t

contains

    !> 'hydrostatic'.
    pure function hydrostatic_name(self) result(name)
        !> The estimate.
        class(hydrostatic_start_t), intent(in) :: self
        character(len=:), allocatable :: name
        name = 'hydrostatic'
    end function hydrostatic_name

    !> Hydrostatic estimate of the reactions of a cold solve (nlgs_config_t%start): the
    !> impulses that bring every disk to rest, -M v_free, carried down the contact network
    !> from the top. "Down" is the direction of the total free momentum sum M v_free (gravity
    !> for a packing at rest). A contact supports its upper body: the other disk lies below
    !> along "down" (|n.down| > level), or the other body is a wall that is not above the
    !> disk. The disks are taken from the top (Kahn's order on the support graph, FIFO from
    !> the disks nothing rests on, in index order: deterministic and serial). Each needs the
    !> impulse S = -M v_free - (impulses of the contacts above it) from its supports. Every
    !> support offers three generators, its normal e (from the support to the disk) and the
    !> two edges e +- mu t of its friction cone; S is written as f_1 g_1 + f_2 g_2 with
    !> f >= 0 over the pairs of generators, keeping the pair with the least f_1 + f_2, so
    !> that every impulse set is in its cone (r_n = f, r_t = +-mu f). When no pair holds the
    !> disk, the best aligned generator alone takes max(S.g, 0). Moments start at zero and
    !> the torques of the tangential impulses are left to the sweeps. With two supports
    !> holding every disk without friction (a frictionless pyramid, test_nlgs) this is the
    !> solution of the step; elsewhere it is a start that already carries the weight to the
    !> floor.
    subroutine hydrostatic_guess(self, cs, list, im, vfree)
        !> The estimate (no settings).
        class(hydrostatic_start_t), intent(in) :: self
        !> Contacts (frames, friction); the reactions of list are set.
        type(contact_set_t), intent(inout) :: cs
        !> The contacts of the solve, all with zero reactions.
        integer, intent(in) :: list(:)
        !> Inverse mass per DOF (3, n_disks).
        real(wp), intent(in) :: im(:, :)
        !> Free velocities (3, n_disks).
        real(wp), intent(in) :: vfree(:, :)
        ! a contact is horizontal when |n.down| <= level (then only a wall supports)
        real(wp), parameter :: level = 1.0e-9_wp
        integer, allocatable :: upper(:), lower(:), first(:), sup(:), n_above(:), queue(:)
        real(wp), allocatable :: e(:, :), acc(:, :)
        real(wp) :: down(2), dn, s(2), det, f1, f2, best, fbest(2), gj(2), gl(2)
        integer :: nd, n, a, k, i, c, head, tail, j, l, jb, lb, u, m
        nd = size(vfree, 2)
        n = size(list)
        down = 0.0_wp
        do i = 1, nd
            do c = 1, 2
                if (im(c, i) > 0.0_wp) down(c) = down(c) + vfree(c, i)/im(c, i)
            end do
        end do
        if (norm2(down) <= 0.0_wp) return
        down = down/norm2(down)
        allocate (upper(n), lower(n), e(2, n))
        allocate (first(nd + 1), source=0)
        allocate (n_above(nd), source=0)
        do a = 1, n
            k = list(a)
            dn = cs%nrm(1, k)*down(1) + cs%nrm(2, k)*down(2)
            upper(a) = 0
            lower(a) = 0
            e(:, a) = cs%nrm(:, k)
            if (dn < -level .or. (cs%i1(k) <= 0 .and. dn <= level)) then
                ! i2 rests on i1 (a disk below, or a floor or side wall)
                upper(a) = cs%i2(k)
                lower(a) = cs%i1(k)
            else if (dn > level .and. cs%i1(k) > 0) then
                upper(a) = cs%i1(k)
                lower(a) = cs%i2(k)
                e(:, a) = -cs%nrm(:, k)
            end if
            if (upper(a) > 0) first(upper(a)) = first(upper(a)) + 1
            if (lower(a) > 0) n_above(lower(a)) = n_above(lower(a)) + 1
        end do
        ! supports of disk u: sup(first(u) : first(u + 1) - 1), positions in list
        do i = nd, 1, -1
            first(i + 1) = first(i)
        end do
        first(1) = 1
        do i = 1, nd
            first(i + 1) = first(i + 1) + first(i)
        end do
        allocate (sup(n))
        block
            integer, allocatable :: fill(:)
            allocate (fill, source=first(1:nd))
            do a = 1, n
                if (upper(a) <= 0) cycle
                sup(fill(upper(a))) = a
                fill(upper(a)) = fill(upper(a)) + 1
            end do
        end block
        allocate (acc(2, nd), source=0.0_wp)
        allocate (queue(nd))
        tail = 0
        do i = 1, nd
            if (n_above(i) == 0) then
                tail = tail + 1
                queue(tail) = i
            end if
        end do
        head = 0
        do while (head < tail)
            head = head + 1
            u = queue(head)
            m = first(u + 1) - first(u)
            if (m > 0 .and. all(im(1:2, u) > 0.0_wp)) then
                s = -vfree(1:2, u)/im(1:2, u) - acc(:, u)
                ! generators: the normal and the two edges of the friction cone of each support
                best = huge(1.0_wp)
                jb = 0
                lb = 0
                do j = 3*first(u) - 2, 3*first(u + 1) - 3
                    gj = generator(j)
                    do l = j + 1, 3*first(u + 1) - 3
                        gl = generator(l)
                        det = gj(1)*gl(2) - gj(2)*gl(1)
                        if (abs(det) <= level) cycle
                        f1 = (s(1)*gl(2) - s(2)*gl(1))/det
                        f2 = (gj(1)*s(2) - gj(2)*s(1))/det
                        if (f1 >= 0.0_wp .and. f2 >= 0.0_wp .and. f1 + f2 < best) then
                            best = f1 + f2
                            jb = j
                            lb = l
                            fbest = [f1, f2]
                        end if
                    end do
                end do
                if (jb == 0) then
                    ! no pair holds the disk: the best aligned support alone
                    jb = 3*first(u) - 1
                    do j = 3*first(u) - 2, 3*first(u + 1) - 3
                        if (dot_product(s, generator(j)) > dot_product(s, generator(jb))) jb = j
                    end do
                    call set(jb, max(dot_product(s, generator(jb)), 0.0_wp))
                else
                    call set(jb, fbest(1))
                    call set(lb, fbest(2))
                end if
            end if
            do j = first(u), first(u + 1) - 1
                l = lower(sup(j))
                if (l <= 0) cycle
                n_above(l) = n_above(l) - 1
                if (n_above(l) == 0) then
                    tail = tail + 1
                    queue(tail) = l
                end if
            end do
        end do
    contains
        ! generator q: 3 per support, support sup((q + 2)/3), sigma = mod(q + 2, 3) - 1 (0: the normal)
        pure function generator(q) result(v)
            integer, intent(in) :: q
            real(wp) :: v(2)
            integer :: p
            p = sup((q + 2)/3)
            v = e(:, p) + (mod(q + 2, 3) - 1)*cs%mu(list(p))*[-e(2, p), e(1, p)]
        end function generator

        ! impulse f times generator q on its contact (r_n = f, r_t = sigma mu f)
        subroutine set(q, f)
            integer, intent(in) :: q
            real(wp), intent(in) :: f
            integer :: p
            real(wp) :: sigma
            p = sup((q + 2)/3)
            sigma = real(mod(q + 2, 3) - 1, wp)
            cs%r(1, list(p)) = cs%r(1, list(p)) + f
            cs%r(2, list(p)) = cs%r(2, list(p)) + sigma*cs%mu(list(p))*f
            if (lower(p) > 0) acc(:, lower(p)) = acc(:, lower(p)) - f*generator(q)
        end subroutine set
    end subroutine hydrostatic_guess

end module dem_cold_start
