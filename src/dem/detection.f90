!> Contact detection: linked-cell broad phase (O(N)) and exact narrow phase for disk-disk and
!> disk-wall pairs within an alert distance.
!>
!> Cells are squares of side max diameter + alert (enlarged if the bounding box would need more
!> than 4 N + 64 cells), built by a counting sort of the disks. A disk meets only disks of its
!> own and the 8 surrounding cells; each cell also lists the walls that pass within reach of it.
!> Candidates of each owner disk are sorted so that the list comes out in the contact order of
!> `dem_contacts`, which matches them with the previous list for the warm start.
module dem_detection
    use core_kinds, only: wp, i8
    use dem_contacts, only: contact_set_t, contacts_begin_detection, contacts_append
    use dem_walls, only: segment_closest_point
    implicit none
    private
    public :: detector_t, detect_contacts, detect_brute_force, detector_bytes

    !> Reusable grid of the broad phase.
    type :: detector_t
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
        !> Walls near cell c are wall_list(wall_start(c):wall_start(c+1)-1).
        integer, allocatable :: wall_list(:), wall_start(:)
        !> Candidate buffer of one owner: other body, normal, gap.
        integer, allocatable :: cand(:)
        !> Candidate normals (2, :) and gaps.
        real(wp), allocatable :: cand_n(:, :), cand_gap(:)
    end type detector_t

contains

    !> Find every disk-disk and disk-wall pair with gap <= alert; the new list replaces the
    !> current one in cs, with reactions and statuses carried over by pair (warm start).
    subroutine detect_contacts(det, x, y, radius, alert, wx1, wy1, wx2, wy2, cs)
        !> Broad-phase workspace.
        type(detector_t), intent(inout) :: det
        !> Disk centres and radii [m].
        real(wp), intent(in) :: x(:), y(:), radius(:)
        !> Alert distance [m] (>= 0).
        real(wp), intent(in) :: alert
        !> Wall end points [m].
        real(wp), intent(in) :: wx1(:), wy1(:), wx2(:), wy2(:)
        !> Contacts.
        type(contact_set_t), intent(inout) :: cs
        integer :: i, n
        call contacts_begin_detection(cs)
        n = size(x)
        if (n == 0) return
        call build_grid(det, x, y, radius, alert)
        call build_wall_lists(det, maxval(radius) + alert, wx1, wy1, wx2, wy2)
        if (.not. allocated(det%cand)) allocate (det%cand(64), det%cand_n(2, 64), det%cand_gap(64))
        do i = 1, n
            call owner_candidates(det, i, x, y, radius, alert, wx1, wy1, wx2, wy2, cs)
        end do
    end subroutine detect_contacts

    !> Grid geometry and counting sort of the disks by cell.
    subroutine build_grid(det, x, y, radius, alert)
        type(detector_t), intent(inout) :: det
        real(wp), intent(in) :: x(:), y(:), radius(:), alert
        real(wp) :: ex, ey, limit
        integer :: i, n, c, ncell
        n = size(x)
        det%x0 = minval(x)
        det%y0 = minval(y)
        ex = maxval(x) - det%x0
        ey = maxval(y) - det%y0
        limit = real(4*n + 64, wp)
        det%cell = 2.0_wp*maxval(radius) + alert
        det%cell = max(det%cell, sqrt((ex + det%cell)*(ey + det%cell)/limit))
        det%inv_cell = 1.0_wp/det%cell
        det%ncx = int(ex/det%cell) + 1
        det%ncy = int(ey/det%cell) + 1
        ncell = det%ncx*det%ncy
        call resize(det%cell_of, n)
        call resize(det%sorted, n)
        call resize(det%start, ncell + 1)
        det%start = 0
        do i = 1, n
            c = cell_index(det, x(i), y(i))
            det%cell_of(i) = c
            det%start(c + 1) = det%start(c + 1) + 1
        end do
        det%start(1) = 1
        do c = 1, ncell
            det%start(c + 1) = det%start(c + 1) + det%start(c)
        end do
        ! fill, then shift the starts back
        do i = 1, n
            c = det%cell_of(i)
            det%sorted(det%start(c)) = i
            det%start(c) = det%start(c) + 1
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
        integer, allocatable :: pos(:)
        integer :: ncell, k, c
        ncell = det%ncx*det%ncy
        call resize(det%wall_start, ncell + 1)
        det%wall_start = 0
        if (size(wx1) == 0) then
            det%wall_start = 1
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
        ! pass 2: store, pos(c + 1) being the next free slot of cell c
        pos = det%wall_start(1:ncell + 1)
        pos(2:ncell + 1) = pos(1:ncell)
        do k = 1, size(wx1)
            call visit_wall_cells(det, k, reach, wx1(k), wy1(k), wx2(k), wy2(k), pos, fill=.true.)
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
                if (hypot(px - qx, py - qy) > lim) cycle
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

    !> Candidates of owner disk i (walls near its cell, disks j > i in the 9 cells around it),
    !> sorted and appended to the list.
    subroutine owner_candidates(det, i, x, y, radius, alert, wx1, wy1, wx2, wy2, cs)
        type(detector_t), intent(inout) :: det
        integer, intent(in) :: i
        real(wp), intent(in) :: x(:), y(:), radius(:), alert, wx1(:), wy1(:), wx2(:), wy2(:)
        type(contact_set_t), intent(inout) :: cs
        integer :: m, c, cx, cy, dx, dy, p, j, k
        real(wp) :: nx, ny, gap
        logical :: hit
        m = 0
        c = det%cell_of(i)
        do p = det%wall_start(c), det%wall_start(c + 1) - 1
            k = det%wall_list(p)
            call disk_wall(x(i), y(i), radius(i), wx1(k), wy1(k), wx2(k), wy2(k), alert, hit, nx, ny, gap)
            if (hit) call push(det, m, -k, nx, ny, gap)
        end do
        cx = mod(c - 1, det%ncx)
        cy = (c - 1)/det%ncx
        do dy = max(cy - 1, 0), min(cy + 1, det%ncy - 1)
            do dx = max(cx - 1, 0), min(cx + 1, det%ncx - 1)
                c = dx + det%ncx*dy + 1
                do p = det%start(c), det%start(c + 1) - 1
                    j = det%sorted(p)
                    if (j <= i) cycle
                    call disk_disk(x(i), y(i), radius(i), x(j), y(j), radius(j), alert, hit, nx, ny, gap)
                    if (.not. hit) cycle
                    if (m == size(det%cand)) then
                        call push(det, m, j, nx, ny, gap)
                    else
                        m = m + 1
                        det%cand(m) = j
                        det%cand_n(1, m) = nx
                        det%cand_n(2, m) = ny
                        det%cand_gap(m) = gap
                    end if
                end do
            end do
        end do
        call emit_sorted(det, m, i, cs)
    end subroutine owner_candidates

    !> Append one candidate to the buffer (grown as needed).
    subroutine push(det, m, other, nx, ny, gap)
        type(detector_t), intent(inout) :: det
        integer, intent(inout) :: m
        integer, intent(in) :: other
        real(wp), intent(in) :: nx, ny, gap
        integer, allocatable :: ti(:)
        real(wp), allocatable :: tn(:, :), tg(:)
        if (m == size(det%cand)) then
            allocate (ti(2*m), tn(2, 2*m), tg(2*m))
            ti(1:m) = det%cand(1:m)
            tn(:, 1:m) = det%cand_n(:, 1:m)
            tg(1:m) = det%cand_gap(1:m)
            call move_alloc(ti, det%cand)
            call move_alloc(tn, det%cand_n)
            call move_alloc(tg, det%cand_gap)
        end if
        m = m + 1
        det%cand(m) = other
        det%cand_n(:, m) = [nx, ny]
        det%cand_gap(m) = gap
    end subroutine push

    !> Insertion sort of the m candidates of owner i by the other body (walls, negative,
    !> first), then append them to the list.
    subroutine emit_sorted(det, m, i, cs)
        type(detector_t), intent(inout) :: det
        integer, intent(in) :: m, i
        type(contact_set_t), intent(inout) :: cs
        integer :: a, b, key
        real(wp) :: nrm(2), gap
        do a = 2, m
            key = det%cand(a)
            nrm = det%cand_n(:, a)
            gap = det%cand_gap(a)
            b = a - 1
            do while (b >= 1)
                if (det%cand(b) <= key) exit
                det%cand(b + 1) = det%cand(b)
                det%cand_n(:, b + 1) = det%cand_n(:, b)
                det%cand_gap(b + 1) = det%cand_gap(b)
                b = b - 1
            end do
            det%cand(b + 1) = key
            det%cand_n(:, b + 1) = nrm
            det%cand_gap(b + 1) = gap
        end do
        do a = 1, m
            if (det%cand(a) < 0) then
                call contacts_append(cs, det%cand(a), i, det%cand_n(1, a), det%cand_n(2, a), det%cand_gap(a))
            else
                call contacts_append(cs, i, det%cand(a), det%cand_n(1, a), det%cand_n(2, a), det%cand_gap(a))
            end if
        end do
    end subroutine emit_sorted

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
        d = hypot(xc - qx, yc - qy)
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
        b = 4_i8*(isize(det%cell_of) + isize(det%sorted) + isize(det%start) + isize(det%wall_list) &
                  + isize(det%wall_start) + isize(det%cand))
        if (allocated(det%cand_n)) b = b + 8_i8*(size(det%cand_n) + size(det%cand_gap))
    contains
        pure integer(i8) function isize(a)
            integer, allocatable, intent(in) :: a(:)
            isize = 0_i8
            if (allocated(a)) isize = size(a)
        end function isize
    end function detector_bytes

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
end module dem_detection
