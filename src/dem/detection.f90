!> Contact detection: linked-cell broad phase (O(N)) and exact narrow phase for disk-disk and
!> disk-wall pairs within an alert distance.
!>
!> Cells are squares of side max diameter + alert (enlarged if the bounding box would need more
!> than 4 N + 64 cells), built by a counting sort of the disks that also copies their centres
!> and radii in cell order (the broad phase then reads contiguous memory: the three cells of a
!> row of neighbours are one range). A disk meets only disks of its own and the 8 surrounding
!> cells; each cell also lists the walls that pass within reach of it. No allocation once the
!> work arrays have reached their size.
!> Candidates of each owner disk are sorted so that the list comes out in the contact order of
!> `dem_contacts`, which matches them with the previous list for the warm start.
!>
!> OpenMP: the owners are scanned in rounds of at most `scan_round` owners per thread; in a round
!> each thread scans a contiguous range of owners (the round cut in equal parts, in thread
!> order). The first thread appends its pairs straight to the contact list, as the serial
!> scan does; each other thread fills its own pair list, and after a barrier these lists are
!> stored in the contact list after the first thread's, in range order (offsets by prefix
!> sums), each thread storing its own. That is the serial order, with the same arithmetic per
!> pair: the list (pairs, order, normals, gaps, reactions carried over) is the same bit for bit
!> for any number of threads. The extra memory (the pair lists) is bounded by the round, not
!> by N, and a step has few synchronisations (three per round: each costs a time slice when
!> the cores are shared with other jobs). With one thread, or fewer than
!> scan_min owners per thread, the serial scan appends straight to the list.
!>
!> Coordinates must lie in the box |x|, |y| <= coordinate_limit(smallest radius): there a
!> coordinate is known to 1e-6 of the smallest radius, and the grid and gap arithmetic cannot
!> overflow. Outside it (or for a non-finite coordinate), `detect_contacts` finds nothing and
!> returns an error instead of building a grid it cannot index.
module dem_detection
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use core_kinds, only: wp, i8
    use core_error, only: error_t, make_error
    use dem_contacts, only: contact_set_t, contacts_begin_detection, contacts_append, &
                            contacts_append_owner, contacts_extend, contacts_fill
    use dem_walls, only: segment_closest_point
!$  use omp_lib, only: omp_get_max_threads, omp_get_num_threads, omp_get_thread_num
    implicit none
    private
    public :: detector_t, detect_contacts, detect_brute_force, detector_bytes, coordinate_limit

    !> Fewest owners per thread for the parallel scan (fewer threads below).
    integer, parameter :: scan_min = 512

    !> Pairs found by one thread in a round, in contact order (work arrays).
    type :: pair_list_t
        !> Number of pairs.
        integer :: n = 0
        !> First and second body of each pair (as in contact_set_t).
        integer, allocatable :: i1(:), i2(:)
        !> Normals (2, :) and gaps.
        real(wp), allocatable :: nrm(:, :), gap(:)
    end type pair_list_t

    !> Work arrays of one thread of the scan.
    type :: scan_work_t
        !> Candidate buffer of one owner: other body.
        integer, allocatable :: cand(:)
        !> Candidate normals (2, :) and gaps.
        real(wp), allocatable :: cand_n(:, :), cand_gap(:)
        !> Pairs found in the current round (parallel scan only).
        type(pair_list_t) :: found
    end type scan_work_t

    !> Reusable grid of the broad phase.
    type :: detector_t
        !> Owners scanned per thread and per round of the parallel scan (bounds its pair
        !> lists; a test lowers it to have several rounds on a small problem).
        integer :: scan_round = 65536
        !> Cell side [m] and its inverse [1/m].
        real(wp) :: cell = 0.0_wp, inv_cell = 0.0_wp
        !> Lower-left corner of the grid [m].
        real(wp) :: x0 = 0.0_wp, y0 = 0.0_wp
        !> Cells along x and y.
        integer :: ncx = 0, ncy = 0
        !> Cell of each disk (1-based, column-major in (cx, cy)).
        integer, allocatable :: cell_of(:)
        !> Disks sorted by cell; disks of cell c are sorted(start(c):start(c+1)-1).
        integer, allocatable :: sorted(:), start(:)
        !> Centres and radii of the disks in cell order: xs(p) = x(sorted(p)).
        real(wp), allocatable :: xs(:), ys(:), rs(:)
        !> Most disks in one cell (sizes the candidate buffer).
        integer :: max_occupancy = 0
        !> Walls near cell c are wall_list(wall_start(c):wall_start(c+1)-1).
        integer, allocatable :: wall_list(:), wall_start(:)
        !> Fill pointers of the wall lists (work array).
        integer, allocatable :: wall_pos(:)
        !> Work arrays of each thread of the scan.
        type(scan_work_t), allocatable :: work(:)
        !> Slot in the contact list of the first pair of each thread in a round.
        integer, allocatable :: offset(:)
    end type detector_t

contains

    !> Find every disk-disk and disk-wall pair with gap <= alert; the new list replaces the
    !> current one in cs, with reactions and statuses carried over by pair (warm start).
    subroutine detect_contacts(det, x, y, radius, alert, wx1, wy1, wx2, wy2, cs, error)
        !> Broad-phase workspace.
        type(detector_t), intent(inout) :: det
        !> Disk centres and radii [m].
        real(wp), intent(in), contiguous :: x(:), y(:), radius(:)
        !> Alert distance [m] (>= 0).
        real(wp), intent(in) :: alert
        !> Wall end points [m].
        real(wp), intent(in) :: wx1(:), wy1(:), wx2(:), wy2(:)
        !> Contacts.
        type(contact_set_t), intent(inout) :: cs
        !> Set when a coordinate is outside the representable box (the list is then empty).
        type(error_t), allocatable, intent(out), optional :: error
        integer :: need, nt, t
        real(wp) :: limit
        call contacts_begin_detection(cs)
        if (size(x) == 0) return
        limit = coordinate_limit(minval(radius))
        if (.not. (inside(x) .and. inside(y) .and. inside(wx1) .and. inside(wy1) .and. inside(wx2) &
                   .and. inside(wy2))) then
            if (present(error)) call make_error(error, 'contact detection: a coordinate is beyond '// &
                                                'the representable box (|x|, |y| <= 4.5e9 times the '// &
                                                'smallest radius, at most 1e100 m) or is not a number')
            return
        end if
        call build_grid(det, x, y, radius, alert)
        call build_wall_lists(det, maxval(radius) + alert, wx1, wy1, wx2, wy2)
        ! room for every candidate of one owner: its walls and the disks of 9 cells
        need = size(wx1) + 9*det%max_occupancy
        nt = 1
!$      nt = max(1, min(omp_get_max_threads(), size(x)/scan_min))
        if (allocated(det%work)) then
            if (size(det%work) < nt) deallocate (det%work)
        end if
        if (.not. allocated(det%work)) allocate (det%work(nt))
        call resize(det%offset, nt + 1)
        do t = 1, nt
            associate (w => det%work(t))
                if (allocated(w%cand)) then
                    if (size(w%cand) < need) deallocate (w%cand, w%cand_n, w%cand_gap)
                end if
                if (.not. allocated(w%cand)) allocate (w%cand(need), w%cand_n(2, need), w%cand_gap(need))
            end associate
        end do
        if (nt == 1) then
            call scan_owners(1, size(x), alert, det%x0, det%y0, det%inv_cell, det%ncx, det%ncy, x, y, &
                             radius, det%cell_of, det%start, det%sorted, det%xs, det%ys, det%rs, &
                             det%wall_start, det%wall_list, wx1, wy1, wx2, wy2, det%work(1)%cand, &
                             det%work(1)%cand_n, det%work(1)%cand_gap, cs=cs)
        else
            call scan_parallel(det, nt, x, y, radius, alert, wx1, wy1, wx2, wy2, cs)
        end if

    contains

        !> All values finite and within the box.
        pure logical function inside(v)
            real(wp), intent(in) :: v(:)
            inside = all(ieee_is_finite(v))
            if (inside) inside = all(abs(v) <= limit)
        end function inside
    end subroutine detect_contacts

    !> Half-side of the box of representable coordinates [m]: 1e-6 r_min/epsilon (about 4.5e9
    !> r_min), where the rounding of a coordinate is a millionth of the smallest radius r_min,
    !> and at most 1e100 m (squares of distances stay finite), also for r_min = huge (no disks:
    !> the minimum of an empty set) without overflow.
    pure real(wp) function coordinate_limit(r_min) result(limit)
        !> Smallest disk radius [m].
        real(wp), intent(in) :: r_min
        limit = 1.0e100_wp
        if (r_min < limit*(epsilon(1.0_wp)/1.0e-6_wp)) limit = 1.0e-6_wp*(r_min/epsilon(1.0_wp))
    end function coordinate_limit

    !> Grid geometry and counting sort of the disks by cell.
    subroutine build_grid(det, x, y, radius, alert)
        type(detector_t), intent(inout) :: det
        real(wp), intent(in) :: x(:), y(:), radius(:), alert
        real(wp) :: ex, ey, limit
        integer :: i, n, c, ncell, p
        n = size(x)
        det%x0 = minval(x)
        det%y0 = minval(y)
        ex = maxval(x) - det%x0
        ey = maxval(y) - det%y0
        limit = real(4*n + 64, wp)
        det%cell = 2.0_wp*maxval(radius) + alert
        det%cell = max(det%cell, sqrt((ex + det%cell)*(ey + det%cell)/limit))
        ! That bounds the cells of a box wide both ways; a box thinner than a cell one way (disks
        ! in a line: a row falling freely for 1e7 m made 2.8e5 cells for 104) takes the smallest
        ! cell with (ex/cell + 1)(ey/cell + 1) <= limit: the positive root c of
        ! (limit - 1) c^2 - (ex + ey) c - ex ey, times 1 + 1e-12 against its rounding.
        if ((aint(ex/det%cell) + 1.0_wp)*(aint(ey/det%cell) + 1.0_wp) > limit) &
            det%cell = max(det%cell, (1.0_wp + 1.0e-12_wp)*((ex + ey) + sqrt((ex + ey)**2 + 4.0_wp*(limit - 1.0_wp)*ex*ey)) &
                           /(2.0_wp*(limit - 1.0_wp)))
        det%inv_cell = 1.0_wp/det%cell
        det%ncx = int(ex/det%cell) + 1
        det%ncy = int(ey/det%cell) + 1
        ncell = det%ncx*det%ncy
        call resize(det%cell_of, n)
        call resize(det%sorted, n)
        call resize(det%start, ncell + 1)
        call resize_real(det%xs, n)
        call resize_real(det%ys, n)
        call resize_real(det%rs, n)
        det%start = 0
        do i = 1, n
            c = cell_index(det, x(i), y(i))
            det%cell_of(i) = c
            det%start(c + 1) = det%start(c + 1) + 1
        end do
        det%max_occupancy = maxval(det%start(2:ncell + 1))
        det%start(1) = 1
        do c = 1, ncell
            det%start(c + 1) = det%start(c + 1) + det%start(c)
        end do
        ! fill, then shift the starts back
        do i = 1, n
            c = det%cell_of(i)
            p = det%start(c)
            det%sorted(p) = i
            det%xs(p) = x(i)
            det%ys(p) = y(i)
            det%rs(p) = radius(i)
            det%start(c) = p + 1
        end do
        do c = ncell, 1, -1
            det%start(c + 1) = det%start(c)
        end do
        det%start(1) = 1
    end subroutine build_grid

    !> Cell (1-based) holding point (px, py), clamped to the grid.
    pure integer function cell_index(det, px, py) result(c)
        type(detector_t), intent(in) :: det
        real(wp), intent(in) :: px, py
        integer :: cx, cy
        cx = min(max(int((px - det%x0)*det%inv_cell), 0), det%ncx - 1)
        cy = min(max(int((py - det%y0)*det%inv_cell), 0), det%ncy - 1)
        c = cx + det%ncx*cy + 1
    end function cell_index

    !> For each cell, the walls whose distance to the cell centre is at most half the cell
    !> diagonal plus `reach` (max radius + alert): a disk of the cell can only touch those.
    subroutine build_wall_lists(det, reach, wx1, wy1, wx2, wy2)
        type(detector_t), intent(inout) :: det
        real(wp), intent(in) :: reach, wx1(:), wy1(:), wx2(:), wy2(:)
        integer :: ncell, k, c
        ncell = det%ncx*det%ncy
        call resize(det%wall_start, ncell + 1)
        det%wall_start = 0
        if (size(wx1) == 0) then
            det%wall_start = 1
            ! allocated all the same: it is passed to scan_owners
            call resize(det%wall_list, 1)
            return
        end if
        ! pass 1: count the walls of cell c in wall_start(c + 1), then prefix sums
        do k = 1, size(wx1)
            call visit_wall_cells(det, k, reach, wx1(k), wy1(k), wx2(k), wy2(k), det%wall_start)
        end do
        det%wall_start(1) = 1
        do c = 1, ncell
            det%wall_start(c + 1) = det%wall_start(c + 1) + det%wall_start(c)
        end do
        call resize(det%wall_list, max(det%wall_start(ncell + 1) - 1, 1))
        ! pass 2: store, wall_pos(c + 1) being the next free slot of cell c
        call resize(det%wall_pos, ncell + 1)
        det%wall_pos(2:ncell + 1) = det%wall_start(1:ncell)
        do k = 1, size(wx1)
            call visit_wall_cells(det, k, reach, wx1(k), wy1(k), wx2(k), wy2(k), det%wall_pos, &
                                  fill=.true.)
        end do
    end subroutine build_wall_lists

    !> Visit the cells wall k may reach: count[c + 1] += 1, or (fill) store k at slot
    !> count[c + 1] of wall_list and advance it.
    subroutine visit_wall_cells(det, k, reach, x1, y1, x2, y2, count, fill)
        type(detector_t), intent(inout) :: det
        integer, intent(in) :: k
        real(wp), intent(in) :: reach, x1, y1, x2, y2
        integer, intent(inout) :: count(:)
        logical, intent(in), optional :: fill
        integer :: cx, cy, cx0, cx1, cy0, cy1, c
        real(wp) :: px, py, qx, qy, lim
        lim = reach + 0.5_wp*sqrt(2.0_wp)*det%cell
        cx0 = clamp_cell((min(x1, x2) - reach - det%x0)*det%inv_cell, det%ncx)
        cx1 = clamp_cell((max(x1, x2) + reach - det%x0)*det%inv_cell, det%ncx)
        cy0 = clamp_cell((min(y1, y2) - reach - det%y0)*det%inv_cell, det%ncy)
        cy1 = clamp_cell((max(y1, y2) + reach - det%y0)*det%inv_cell, det%ncy)
        do cy = max(cy0, 0), min(cy1, det%ncy - 1)
            do cx = max(cx0, 0), min(cx1, det%ncx - 1)
                px = det%x0 + (cx + 0.5_wp)*det%cell
                py = det%y0 + (cy + 0.5_wp)*det%cell
                call segment_closest_point(x1, y1, x2, y2, px, py, qx, qy)
                if ((px - qx)**2 + (py - qy)**2 > lim**2) cycle
                c = cx + det%ncx*cy + 1
                if (present(fill)) det%wall_list(count(c + 1)) = k
                count(c + 1) = count(c + 1) + 1
            end do
        end do
    end subroutine visit_wall_cells

    !> Cell coordinate floor(s) clamped to [-1, nc] (outside the grid on either side stays
    !> outside; no integer overflow for far walls).
    pure integer function clamp_cell(s, nc) result(c)
        real(wp), intent(in) :: s
        integer, intent(in) :: nc
        c = int(floor(min(max(s, -1.0_wp), real(nc, wp))))
    end function clamp_cell

    !> The scan of all owners on up to nt threads, in rounds (see the module's description): in
    !> each round thread 0 appends the pairs of the first range straight to the contact list,
    !> as the serial scan; every other thread scans its range into its pair list, which then
    !> goes to the slots after those of threads 0 .. t - 1.
    subroutine scan_parallel(det, nt, x, y, radius, alert, wx1, wy1, wx2, wy2, cs)
        type(detector_t), intent(inout) :: det
        integer, intent(in) :: nt
        real(wp), intent(in), contiguous :: x(:), y(:), radius(:)
        real(wp), intent(in) :: alert
        real(wp), intent(in) :: wx1(:), wy1(:), wx2(:), wy2(:)
        type(contact_set_t), intent(inout) :: cs
        integer :: n, base, span, team, t, s, lo, hi
        n = size(x)
        !$omp parallel num_threads(nt) default(shared) private(base, span, team, t, s, lo, hi)
        ! the team may be smaller than asked for: the split follows the team actually formed
        team = 1
        t = 0
!$      team = omp_get_num_threads()
!$      t = omp_get_thread_num()
        base = 0
        do while (base < n)
            span = int(min(int(team, i8)*max(det%scan_round, 1), int(n - base, i8)))
            lo = base + int((int(t, i8)*span)/team) + 1
            hi = base + int((int(t + 1, i8)*span)/team)
            associate (w => det%work(t + 1))
                if (t == 0) then
                    ! the other threads leave the contact list alone until the barrier
                    call scan_owners(lo, hi, alert, det%x0, det%y0, det%inv_cell, det%ncx, det%ncy, x, y, &
                                     radius, det%cell_of, det%start, det%sorted, det%xs, det%ys, det%rs, &
                                     det%wall_start, det%wall_list, wx1, wy1, wx2, wy2, w%cand, w%cand_n, &
                                     w%cand_gap, cs=cs)
                else
                    w%found%n = 0
                    call scan_owners(lo, hi, alert, det%x0, det%y0, det%inv_cell, det%ncx, det%ncy, x, y, &
                                     radius, det%cell_of, det%start, det%sorted, det%xs, det%ys, det%rs, &
                                     det%wall_start, det%wall_list, wx1, wy1, wx2, wy2, w%cand, w%cand_n, &
                                     w%cand_gap, found=w%found)
                end if
            end associate
            !$omp barrier
            !$omp single
            det%offset(2) = cs%n + 1
            do s = 2, team
                det%offset(s + 1) = det%offset(s) + det%work(s)%found%n
            end do
            call contacts_extend(cs, det%offset(team + 1) - det%offset(2))
            !$omp end single
            if (t > 0) then
                associate (f => det%work(t + 1)%found)
                    call contacts_fill(cs, det%offset(t + 1), f%i1(1:f%n), f%i2(1:f%n), f%nrm(:, 1:f%n), &
                                       f%gap(1:f%n))
                end associate
            end if
            ! the slots are filled before thread 0 appends again
            !$omp barrier
            base = base + span
        end do
        !$omp end parallel
    end subroutine scan_parallel

    !> Broad and narrow phase, owner by owner (i = 1, 2, ...): the walls listed for the cell of
    !> disk i, then the disks j > i of the 9 cells around it (three contiguous ranges of the
    !> cell-ordered arrays); the hits are sorted by the other body and appended to the contact
    !> list cs, or to the pair list found (one of the two is given). Owners lo to hi.
    !> The grid is passed as plain arrays so that the compiler keeps them in registers.
    subroutine scan_owners(lo, hi, alert, x0, y0, inv_cell, ncx, ncy, x, y, radius, cell_of, start, &
                           sorted, xs, ys, rs, wall_start, wall_list, wx1, wy1, wx2, wy2, &
                           cand, cand_n, cand_gap, cs, found)
        integer, intent(in) :: lo, hi
        real(wp), intent(in) :: alert, x0, y0, inv_cell
        integer, intent(in) :: ncx, ncy
        real(wp), intent(in), contiguous :: x(:), y(:), radius(:)
        integer, intent(in), contiguous :: cell_of(:), start(:), sorted(:)
        integer, intent(in), contiguous :: wall_start(:), wall_list(:)
        real(wp), intent(in), contiguous :: xs(:), ys(:), rs(:)
        real(wp), intent(in) :: wx1(:), wy1(:), wx2(:), wy2(:)
        integer, intent(inout), contiguous :: cand(:)
        real(wp), intent(inout), contiguous :: cand_n(:, :), cand_gap(:)
        type(contact_set_t), intent(inout), optional :: cs
        type(pair_list_t), intent(inout), optional :: found
        integer :: i, m, c, cx, cy, dy, p, j, k, row
        real(wp) :: nx, ny, gap, xi, yi, ri
        logical :: hit
        do i = lo, hi
            m = 0
            xi = x(i)
            yi = y(i)
            ri = radius(i)
            c = cell_of(i)
            do p = wall_start(c), wall_start(c + 1) - 1
                k = wall_list(p)
                call disk_wall(xi, yi, ri, wx1(k), wy1(k), wx2(k), wy2(k), alert, hit, nx, ny, gap)
                if (.not. hit) cycle
                m = m + 1
                cand(m) = -k
                cand_n(1, m) = nx
                cand_n(2, m) = ny
                cand_gap(m) = gap
            end do
            ! cell coordinates from the position (same clamping as cell_index, no integer division)
            cx = min(max(int((xi - x0)*inv_cell), 0), ncx - 1)
            cy = min(max(int((yi - y0)*inv_cell), 0), ncy - 1)
            do dy = max(cy - 1, 0), min(cy + 1, ncy - 1)
                row = ncx*dy + 1
                do p = start(row + max(cx - 1, 0)), start(row + min(cx + 1, ncx - 1) + 1) - 1
                    j = sorted(p)
                    if (j <= i) cycle
                    ! xs(p) = x(j) etc.: the same numbers as the brute-force search
                    call disk_disk(xi, yi, ri, xs(p), ys(p), rs(p), alert, hit, nx, ny, gap)
                    if (.not. hit) cycle
                    m = m + 1
                    cand(m) = j
                    cand_n(1, m) = nx
                    cand_n(2, m) = ny
                    cand_gap(m) = gap
                end do
            end do
            call sort_candidates(m, cand, cand_n, cand_gap)
            if (present(cs)) then
                call contacts_append_owner(cs, i, cand(1:m), cand_n(:, 1:m), cand_gap(1:m))
            else
                call list_owner(found, i, cand(1:m), cand_n(:, 1:m), cand_gap(1:m))
            end if
        end do
    end subroutine scan_owners

    !> Append the sorted candidates of one owner to a pair list, as contacts_append_owner
    !> appends them to the contact list.
    pure subroutine list_owner(found, owner, other, nrm, gap)
        type(pair_list_t), intent(inout) :: found
        integer, intent(in) :: owner, other(:)
        real(wp), intent(in) :: nrm(:, :), gap(:)
        integer :: a, k
        if (found%n + size(other) > isize(found%i1)) call grow_list(found, found%n + size(other))
        do a = 1, size(other)
            k = found%n + a
            if (other(a) < 0) then
                found%i1(k) = other(a)
                found%i2(k) = owner
            else
                found%i1(k) = owner
                found%i2(k) = other(a)
            end if
            found%nrm(1, k) = nrm(1, a)
            found%nrm(2, k) = nrm(2, a)
            found%gap(k) = gap(a)
        end do
        found%n = found%n + size(other)
    end subroutine list_owner

    !> Room for at least m pairs in a pair list (keeps the first n).
    pure subroutine grow_list(found, m)
        type(pair_list_t), intent(inout) :: found
        integer, intent(in) :: m
        integer, allocatable :: ti1(:), ti2(:)
        real(wp), allocatable :: tn(:, :), tg(:)
        integer :: cap, n
        n = found%n
        cap = max(isize(found%i1) + isize(found%i1)/4, m, 1024)
        allocate (ti1(cap), ti2(cap), tn(2, cap), tg(cap))
        if (n > 0) then
            ti1(1:n) = found%i1(1:n)
            ti2(1:n) = found%i2(1:n)
            tn(:, 1:n) = found%nrm(:, 1:n)
            tg(1:n) = found%gap(1:n)
        end if
        call move_alloc(ti1, found%i1)
        call move_alloc(ti2, found%i2)
        call move_alloc(tn, found%nrm)
        call move_alloc(tg, found%gap)
    end subroutine grow_list

    !> Insertion sort of the m candidates of one owner by the other body (walls, negative,
    !> first); they come nearly sorted when disks are numbered by position.
    pure subroutine sort_candidates(m, cand, cand_n, cand_gap)
        integer, intent(in) :: m
        integer, intent(inout) :: cand(:)
        real(wp), intent(inout) :: cand_n(:, :), cand_gap(:)
        integer :: a, b, key
        real(wp) :: nx, ny, gap
        do a = 2, m
            key = cand(a)
            if (cand(a - 1) <= key) cycle
            nx = cand_n(1, a)
            ny = cand_n(2, a)
            gap = cand_gap(a)
            b = a - 1
            do while (b >= 1)
                if (cand(b) <= key) exit
                cand(b + 1) = cand(b)
                cand_n(1, b + 1) = cand_n(1, b)
                cand_n(2, b + 1) = cand_n(2, b)
                cand_gap(b + 1) = cand_gap(b)
                b = b - 1
            end do
            cand(b + 1) = key
            cand_n(1, b + 1) = nx
            cand_n(2, b + 1) = ny
            cand_gap(b + 1) = gap
        end do
    end subroutine sort_candidates

    !> Reference detection by testing every pair (O(N^2)); same output and order as
    !> detect_contacts. For tests and small systems.
    subroutine detect_brute_force(x, y, radius, alert, wx1, wy1, wx2, wy2, cs)
        !> Disk centres and radii [m].
        real(wp), intent(in) :: x(:), y(:), radius(:)
        !> Alert distance [m].
        real(wp), intent(in) :: alert
        !> Wall end points [m].
        real(wp), intent(in) :: wx1(:), wy1(:), wx2(:), wy2(:)
        !> Contacts.
        type(contact_set_t), intent(inout) :: cs
        integer :: i, j, k
        real(wp) :: nx, ny, gap
        logical :: hit
        call contacts_begin_detection(cs)
        do i = 1, size(x)
            do k = size(wx1), 1, -1
                call disk_wall(x(i), y(i), radius(i), wx1(k), wy1(k), wx2(k), wy2(k), alert, hit, nx, ny, gap)
                if (hit) call contacts_append(cs, -k, i, nx, ny, gap)
            end do
            do j = i + 1, size(x)
                call disk_disk(x(i), y(i), radius(i), x(j), y(j), radius(j), alert, hit, nx, ny, gap)
                if (hit) call contacts_append(cs, i, j, nx, ny, gap)
            end do
        end do
    end subroutine detect_brute_force

    !> Narrow phase disk i - disk j: hit when gap <= alert; normal from i to j.
    pure subroutine disk_disk(xi, yi, ri, xj, yj, rj, alert, hit, nx, ny, gap)
        real(wp), intent(in) :: xi, yi, ri, xj, yj, rj, alert
        logical, intent(out) :: hit
        real(wp), intent(out) :: nx, ny, gap
        real(wp) :: dx, dy, d2, d, reach
        dx = xj - xi
        dy = yj - yi
        d2 = dx*dx + dy*dy
        reach = ri + rj + alert
        hit = d2 <= reach*reach
        nx = 0.0_wp
        ny = 1.0_wp
        gap = 0.0_wp
        if (.not. hit) return
        d = sqrt(d2)
        if (d > 0.0_wp) then
            nx = dx/d
            ny = dy/d
        end if
        gap = d - ri - rj
    end subroutine disk_disk

    !> Narrow phase wall - disk: hit when gap <= alert; normal from the wall into the disk.
    pure subroutine disk_wall(xc, yc, r, x1, y1, x2, y2, alert, hit, nx, ny, gap)
        real(wp), intent(in) :: xc, yc, r, x1, y1, x2, y2, alert
        logical, intent(out) :: hit
        real(wp), intent(out) :: nx, ny, gap
        real(wp) :: qx, qy, d, e
        call segment_closest_point(x1, y1, x2, y2, xc, yc, qx, qy)
        ! (sqrt rather than hypot: no overflow at lengths of a disk's size, and libm's hypot
        ! was 1.5 % of the 200-disk deposit's time)
        d = sqrt((xc - qx)**2 + (yc - qy)**2)
        hit = d <= r + alert
        gap = d - r
        if (d > 0.0_wp) then
            nx = (xc - qx)/d
            ny = (yc - qy)/d
        else
            e = hypot(x2 - x1, y2 - y1)
            nx = -(y2 - y1)/e
            ny = (x2 - x1)/e
        end if
    end subroutine disk_wall

    !> Memory held by the detection workspace [bytes].
    pure integer(i8) function detector_bytes(det) result(b)
        !> Detection workspace.
        type(detector_t), intent(in) :: det
        integer :: t
        b = 4_i8*(isize(det%cell_of) + isize(det%sorted) + isize(det%start) + isize(det%wall_list) &
                  + isize(det%wall_start) + isize(det%wall_pos) + isize(det%offset))
        if (allocated(det%xs)) b = b + 8_i8*(size(det%xs) + size(det%ys) + size(det%rs))
        if (.not. allocated(det%work)) return
        do t = 1, size(det%work)
            associate (w => det%work(t))
                ! candidates: 4 + 3 x 8 bytes; pairs found: 2 x 4 + 3 x 8 bytes
                b = b + 28_i8*isize(w%cand) + 32_i8*isize(w%found%i1)
            end associate
        end do
    end function detector_bytes

    !> Size of an integer work array, 0 when not allocated.
    pure integer function isize(a)
        integer, allocatable, intent(in) :: a(:)
        isize = 0
        if (allocated(a)) isize = size(a)
    end function isize

    !> Make sure an integer work array has at least m entries.
    subroutine resize(a, m)
        integer, allocatable, intent(inout) :: a(:)
        integer, intent(in) :: m
        if (allocated(a)) then
            if (size(a) >= m) return
            deallocate (a)
        end if
        allocate (a(m))
    end subroutine resize

    !> Make sure a real work array has at least m entries.
    subroutine resize_real(a, m)
        real(wp), allocatable, intent(inout) :: a(:)
        integer, intent(in) :: m
        if (allocated(a)) then
            if (size(a) >= m) return
            deallocate (a)
        end if
        allocate (a(m))
    end subroutine resize_real
end module dem_detection
