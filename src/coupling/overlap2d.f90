!> Overlap regions of the 2D Arlequin coupling and their weight alpha(x, y) (doc/continuum.md,
!> "Arlequin coupling in 2D"; doc/theory.md section 6.9).
!>
!> A region is a simple polygon (an axis-aligned box is the polygon of its four corners, edges
!> bottom, right, top, left in that order). Each edge is tagged: on the FE side (the overlap
!> meets the FE-only zone there), on the particle side (it meets the particle-only zone), or
!> neither (a lateral edge, e.g. the ends of a band). Inside the region, with d_fe and d_p the
!> distances to the nearest FE-side and particle-side edges,
!>   xi = d_fe / (d_fe + d_p)  in [0, 1],   alpha = clip(r(xi), alpha_min, 1 - alpha_min),
!> with the ramps r of coupling_weights (constant c, linear 1 - xi, cubic 1 - 3 xi^2 + 2 xi^3):
!> alpha is 1 - alpha_min on the FE side, alpha_min on the particle side. For a band between
!> two parallel edges xi is the reduced coordinate across the band, the 1D weight exactly.
!> The constant shape needs no tags. Outside the region each side sees its own zone: the FE
!> weight is 1 (`alpha_fe`), the disks' alpha is 0 (`alpha_disk`, weighted mass (1 - alpha) m).
!> The boundary belongs to the region (a point within 1e-12 of the region's size of an edge).
!>
!> Several disjoint regions (e.g. the two bands of an interface between two blocks) form an
!> `overlap_set_t`: a point takes the weight of the first region holding it, and 1 (FE) or
!> 0 (disks) outside all of them. Regions that share more than boundary points would weight
!> the same material twice: `regions_overlap` tells them apart from regions that only touch.
!> Both types extend the abstract `weight_field_t` that the weighted assembly takes; its
!> bindings also give the ramp the results record (`ramp`) and the points just beyond the
!> particle-side edges where coupling_arlequin2d checks that the continuum stops
!> (`particle_side_probes`).
module coupling_overlap2d
    use core_kinds, only: wp
    use core_constants, only: relative_roundoff
    use core_error, only: error_t, make_error
    use core_strings, only: to_str
    use coupling_weights, only: weight_config_t, overlap_weight_t, make_weight
    implicit none
    private
    public :: weight_field_t, overlap2d_t, overlap_set_t, make_box_overlap, make_polygon_overlap, regions_overlap
    public :: crossing_edges

    !> A weight field alpha(x, y) of the 2D coupling.
    type, abstract :: weight_field_t
    contains
        !> Weight of the FE side (1 outside the overlap).
        procedure(weight_at_iface), deferred :: alpha_fe
        !> Weight alpha of a disk (0 outside the overlap; its mass is (1 - alpha) m).
        procedure(weight_at_iface), deferred :: alpha_disk
        !> True when the box (xmin, xmax, ymin, ymax) misses the overlap (alpha_fe = 1 there).
        procedure(weight_misses_iface), deferred :: misses
        !> The disks to couple (alpha > 0: centre in the overlap) and every disk's alpha.
        procedure :: select_disks => field_select_disks
        !> The ramp (shape and floor) of the weight, as the results give it.
        procedure(weight_ramp_iface), deferred :: ramp
        !> Points just outside the particle-side edges, where the continuum must not go on.
        procedure(weight_probes_iface), deferred :: particle_side_probes
        !> Number of the region holding a point, in the order of the deck's region lines (0:
        !> none).
        procedure(region_of_iface), deferred :: region_of
    end type weight_field_t

    abstract interface
        !> The region holding a point.
        pure integer function region_of_iface(self, x, y) result(k)
            import :: weight_field_t, wp
            !> The weight field.
            class(weight_field_t), intent(in) :: self
            !> The point [m].
            real(wp), intent(in) :: x, y
        end function region_of_iface

        !> A weight at a point.
        pure real(wp) function weight_at_iface(self, x, y) result(alpha)
            import :: weight_field_t, wp
            !> The weight field.
            class(weight_field_t), intent(in) :: self
            !> The point [m].
            real(wp), intent(in) :: x, y
        end function weight_at_iface

        !> Whether a box misses the overlap.
        pure logical function weight_misses_iface(self, box)
            import :: weight_field_t, wp
            !> The weight field.
            class(weight_field_t), intent(in) :: self
            !> The box (xmin, xmax, ymin, ymax) [m].
            real(wp), intent(in) :: box(4)
        end function weight_misses_iface

        !> The ramp of a weight field.
        pure function weight_ramp_iface(self) result(ramp)
            import :: weight_field_t, overlap_weight_t
            !> The weight field.
            class(weight_field_t), intent(in) :: self
            !> Its ramp and floor.
            type(overlap_weight_t) :: ramp
        end function weight_ramp_iface

        !> Probe points along the particle-side edges of a weight field.
        pure subroutine weight_probes_iface(self, q, edge, region)
            import :: weight_field_t, wp
            !> The weight field.
            class(weight_field_t), intent(in) :: self
            !> The points (2, n_probes) [m].
            real(wp), allocatable, intent(out) :: q(:, :)
            !> Number of the edge of each point, in its region (n_probes).
            integer, allocatable, intent(out) :: edge(:)
            !> Number of the region of each point in a set (n_probes; 0 for a single region).
            integer, allocatable, intent(out) :: region(:)
        end subroutine weight_probes_iface
    end interface

    !> A polygonal overlap region and its weight (see the module description).
    type, extends(weight_field_t) :: overlap2d_t
        !> Vertices (2, n_vertices), edge k from vertex k to vertex k + 1 (cyclic).
        real(wp), allocatable :: vertex(:, :)
        !> Edge on the FE side (n_vertices).
        logical, allocatable :: fe_edge(:)
        !> Edge on the particle side (n_vertices).
        logical, allocatable :: particle_edge(:)
        !> Ramp r(xi) and floor, over xi in [0, 1] (s_fe = 0, s_particle = 1).
        type(overlap_weight_t) :: weight
        !> Bounding box (xmin, xmax, ymin, ymax) [m].
        real(wp) :: box(4) = 0.0_wp
        !> Distance under which a point is on the boundary [m].
        real(wp) :: tol = 0.0_wp
    contains
        !> True when (x, y) lies in the region (boundary included).
        procedure :: contains => overlap_contains
        !> Reduced coordinate xi in [0, 1] of a point of the region.
        procedure :: reduced => overlap_reduced
        !> Weight of the FE side: alpha in the region, 1 outside.
        procedure :: alpha_fe => overlap_alpha_fe
        !> Weight alpha of a disk: alpha in the region, 0 outside (mass (1 - alpha) m).
        procedure :: alpha_disk => overlap_alpha_disk
        !> True when a box misses the region's bounding box.
        procedure :: misses => overlap_misses
        !> The region's ramp.
        procedure :: ramp => overlap_ramp
        !> Probes just outside the region's particle-side edges (region number 0).
        procedure :: particle_side_probes => overlap_particle_side_probes
        !> 1 for a point of the region, 0 outside.
        procedure :: region_of => overlap_region_of
    end type overlap2d_t

    !> Disjoint overlap regions (see the module description).
    type, extends(weight_field_t) :: overlap_set_t
        !> The regions.
        type(overlap2d_t), allocatable :: regions(:)
    contains
        !> Weight of the first region holding the point, 1 outside all.
        procedure :: alpha_fe => set_alpha_fe
        !> Disk weight of the first region holding the point, 0 outside all.
        procedure :: alpha_disk => set_alpha_disk
        !> True when a box misses every region.
        procedure :: misses => set_misses
        !> The ramp of the first region (the default ramp for an empty set).
        procedure :: ramp => set_ramp
        !> The probes of every region in turn, with its number.
        procedure :: particle_side_probes => set_particle_side_probes
        !> The first region holding the point (0: none).
        procedure :: region_of => set_region_of
    end type overlap_set_t

    !> Names of the edges of a box, in edge order.
    character(len=6), parameter :: box_sides(4) = ['bottom', 'right ', 'top   ', 'left  ']

contains

    !> An axis-aligned box [xmin, xmax] x [ymin, ymax]; fe_side and particle_side name its
    !> edges ('bottom', 'right', 'top', 'left'; empty strings for the constant shape).
    subroutine make_box_overlap(xmin, xmax, ymin, ymax, fe_side, particle_side, weight, region, error)
        !> Extent of the box [m].
        real(wp), intent(in) :: xmin, xmax, ymin, ymax
        !> Side next to the FE-only zone.
        character(len=*), intent(in) :: fe_side
        !> Side next to the particle-only zone.
        character(len=*), intent(in) :: particle_side
        !> Shape, floor and constant value (s_fe and s_particle are ignored).
        type(weight_config_t), intent(in) :: weight
        !> The region.
        type(overlap2d_t), intent(out) :: region
        !> Set on an empty box, an unknown side name or an invalid weight.
        type(error_t), allocatable, intent(out) :: error
        integer :: kf, kp
        if (.not. (xmax > xmin .and. ymax > ymin)) then
            call make_error(error, 'overlap box: empty (need xmin < xmax and ymin < ymax)')
            return
        end if
        kf = side_index(fe_side)
        kp = side_index(particle_side)
        if (kf < 0) then
            call make_error(error, "overlap box: unknown side '"//trim(fe_side)//"' (expected bottom, right, top or left)")
            return
        else if (kp < 0) then
            call make_error(error, "overlap box: unknown side '"//trim(particle_side)// &
                            "' (expected bottom, right, top or left)")
            return
        end if
        call make_polygon_overlap(reshape([xmin, ymin, xmax, ymin, xmax, ymax, xmin, ymax], [2, 4]), &
                                  pack([1, 2, 3, 4], [1, 2, 3, 4] == kf), pack([1, 2, 3, 4], [1, 2, 3, 4] == kp), &
                                  weight, region, error)
    end subroutine make_box_overlap

    !> Index of a box side by name, 0 for an empty name, -1 when unknown.
    pure integer function side_index(name) result(k)
        character(len=*), intent(in) :: name
        if (len_trim(name) == 0) then
            k = 0
        else
            k = findloc(box_sides, trim(name), dim=1)
            if (k == 0) k = -1
        end if
    end function side_index

    !> A polygon (vertices in either orientation, not self-intersecting) with the indices of
    !> its FE-side and particle-side edges (edge k joins vertices k and k + 1).
    subroutine make_polygon_overlap(vertex, fe_edges, particle_edges, weight, region, error)
        !> Vertices (2, n), n >= 3 [m].
        real(wp), intent(in) :: vertex(:, :)
        !> FE-side edges.
        integer, intent(in) :: fe_edges(:)
        !> Particle-side edges.
        integer, intent(in) :: particle_edges(:)
        !> Shape, floor and constant value (s_fe and s_particle are ignored).
        type(weight_config_t), intent(in) :: weight
        !> The region.
        type(overlap2d_t), intent(out) :: region
        !> Set on too few vertices, a repeated vertex (a zero-length edge, the last vertex equal
        !> to the first included), a zero area, edges that cross, touch or fold back on each
        !> other (`crossing_edges`), an edge index out of range or tagged twice,
        !> a ramp without edges on both sides, or an invalid weight.
        type(error_t), allocatable, intent(out) :: error
        type(weight_config_t) :: w
        integer, allocatable :: tags(:)
        integer :: n, k, e, crossing(2)
        real(wp) :: area
        character(len=200) :: buf
        character(len=:), allocatable :: message
        n = size(vertex, 2)
        if (n < 3 .or. size(vertex, 1) /= 2) then
            call make_error(error, 'overlap polygon: needs at least 3 vertices (x, y)')
            return
        end if
        ! A repeated vertex makes a zero-length edge: the edges after it are numbered one
        ! further than the user counted, so the tagged sides would silently be other edges.
        do k = 1, n
            if (all(vertex(:, k) == vertex(:, modulo(k, n) + 1))) then
                call make_error(error, 'overlap polygon: vertices '//to_str(k)//' and '//to_str(modulo(k, n) + 1)// &
                                ' are the same point ('//to_str(vertex(1, k))//', '//to_str(vertex(2, k))// &
                                '): edge '//to_str(k)//' has zero length and would shift the numbering of '// &
                                'the edges after it; give each vertex once (the polygon closes itself: '// &
                                'the last vertex joins the first, do not repeat it)')
                return
            end if
        end do
        ! The inside test, the distances to the tagged edges and the triangulation all take the
        ! boundary for a simple closed curve: a bow-tie would weight its two lobes as one region.
        crossing = crossing_edges(vertex)
        if (crossing(1) > 0) then
            if (crossing(2) == crossing(1) + 1 .or. (crossing(1) == 1 .and. crossing(2) == n)) then
                message = 'edges '//edge_name(crossing(1))//' and '//edge_name(crossing(2))//' fold back on '// &
                          'each other (one runs back along the other)'
            else
                message = 'edges '//edge_name(crossing(1))//' and '//edge_name(crossing(2))//' cross or touch'
            end if
            call make_error(error, 'overlap polygon: '//message//': a region must be a simple polygon, its '// &
                            'vertices given in order around it (either direction), no edge meeting another '// &
                            'except its neighbours at their common vertex; reorder the vertices, or split the '// &
                            'region into several region lines')
            return
        end if
        ! (after the crossing test: the lobes of a symmetric bow-tie have opposite signed areas
        ! that cancel, and 'zero area' named no edge)
        area = 0.0_wp
        do k = 1, n
            area = area + cross(vertex(:, k), vertex(:, modulo(k, n) + 1))
        end do
        if (.not. abs(area) > 0) then
            call make_error(error, 'overlap polygon: zero area')
            return
        end if
        allocate (region%fe_edge(n), region%particle_edge(n), source=.false.)
        tags = [fe_edges, particle_edges]
        do k = 1, size(tags)
            e = tags(k)
            if (e < 1 .or. e > n) then
                write (buf, '(a,i0,a,i0,a)') 'overlap polygon: edge ', e, ' does not exist (edges 1..', n, ')'
            else if (region%fe_edge(e) .or. region%particle_edge(e)) then
                write (buf, '(a,i0,a)') 'overlap polygon: edge ', e, ' is tagged twice'
            else
                if (k <= size(fe_edges)) then
                    region%fe_edge(e) = .true.
                else
                    region%particle_edge(e) = .true.
                end if
                cycle
            end if
            call make_error(error, trim(buf))
            return
        end do
        if (weight%shape /= 'constant' .and. .not. (any(region%fe_edge) .and. any(region%particle_edge))) then
            call make_error(error, 'overlap: a '//trim(weight%shape)//' weight ramps from the FE side '// &
                            'to the particle side: tag at least one edge of each')
            return
        end if
        w = weight
        w%s_fe = 0.0_wp
        w%s_particle = 1.0_wp
        call make_weight(w, region%weight, error)
        if (allocated(error)) return
        region%vertex = vertex
        region%box = [minval(vertex(1, :)), maxval(vertex(1, :)), minval(vertex(2, :)), maxval(vertex(2, :))]
        ! Rounding of coordinates at the scale of the region.
        region%tol = relative_roundoff*max(region%box(2) - region%box(1), region%box(4) - region%box(3))
    contains
        !> 'k (vertex k to k + 1)', the last edge back to vertex 1.
        pure function edge_name(k) result(name)
            integer, intent(in) :: k
            character(len=:), allocatable :: name
            name = to_str(k)//' (vertex '//to_str(k)//' to '//to_str(modulo(k, n) + 1)//')'
        end function edge_name
    end subroutine make_polygon_overlap

    !> The first pair (i, j), i < j, of edges of a polygon that meet where a simple polygon's
    !> edges do not; [0, 0] when there is none (the polygon is simple). Edges that are not
    !> neighbours must not meet at all (a crossing, a vertex on another edge, two equal
    !> vertices); neighbours meet only at their common vertex (one running back along the
    !> other is a fold-back; a vertex on the straight line between its neighbours is fine).
    !> Two edges meet when they are closer than the rounding of the coordinates
    !> (`relative_roundoff` times the larger side of the bounding box). Edge k joins vertex k
    !> to vertex k + 1, the last vertex to the first.
    pure function crossing_edges(vertex) result(edges)
        !> Vertices (2, n), n >= 3 [m].
        real(wp), intent(in) :: vertex(:, :)
        !> The two edges, or [0, 0].
        integer :: edges(2)
        real(wp) :: tol, a(2), b(2), c(2), d(2)
        integer :: n, i, j
        logical :: meet
        edges = 0
        n = size(vertex, 2)
        tol = relative_roundoff*max(maxval(vertex(1, :)) - minval(vertex(1, :)), &
                                    maxval(vertex(2, :)) - minval(vertex(2, :)))
        do i = 1, n - 1
            a = vertex(:, i)
            b = vertex(:, i + 1)
            do j = i + 1, n
                c = vertex(:, j)
                d = vertex(:, modulo(j, n) + 1)
                if (j == i + 1) then
                    ! neighbours through b = c: the far end of either lies on the other
                    meet = segment_distance(d, a, b) <= tol .or. segment_distance(a, c, d) <= tol
                else if (i == 1 .and. j == n) then
                    ! neighbours through a = d
                    meet = segment_distance(b, c, d) <= tol .or. segment_distance(c, a, b) <= tol
                else
                    meet = segments_meet(a, b, c, d, tol)
                end if
                if (meet) then
                    edges = [i, j]
                    return
                end if
            end do
        end do
    end function crossing_edges

    !> Whether the segments [a, b] and [c, d] have a point within tol of each other: they
    !> cross (each one's ends strictly on both sides of the other's line), or an end of one
    !> lies within tol of the other.
    pure logical function segments_meet(a, b, c, d, tol) result(meet)
        real(wp), intent(in) :: a(2), b(2), c(2), d(2), tol
        real(wp) :: o1, o2, o3, o4
        o1 = cross(b - a, c - a)
        o2 = cross(b - a, d - a)
        o3 = cross(d - c, a - c)
        o4 = cross(d - c, b - c)
        meet = ((o1 > 0 .and. o2 < 0) .or. (o1 < 0 .and. o2 > 0)) .and. &
               ((o3 > 0 .and. o4 < 0) .or. (o3 < 0 .and. o4 > 0))
        if (meet) return
        meet = min(segment_distance(c, a, b), segment_distance(d, a, b), segment_distance(a, c, d), &
                   segment_distance(b, c, d)) <= tol
    end function segments_meet

    !> True when the interiors of two regions intersect (a common area, more than the
    !> rounding of the coordinates: the larger `tol` of the two); regions that only touch along
    !> an edge or at a point do not overlap. Each polygon is cut into triangles (ear
    !> clipping), and two triangles overlap when no edge direction of either separates them
    !> (separating axes, exact for convex shapes).
    pure logical function regions_overlap(a, b) result(overlap)
        !> The regions (simple polygons).
        type(overlap2d_t), intent(in) :: a, b
        real(wp), allocatable :: ta(:, :, :), tb(:, :, :)
        real(wp) :: tol
        integer :: i, j
        overlap = .false.
        tol = max(a%tol, b%tol)
        if (a%box(1) >= b%box(2) - tol .or. b%box(1) >= a%box(2) - tol .or. &
            a%box(3) >= b%box(4) - tol .or. b%box(3) >= a%box(4) - tol) return
        call triangulate(a%vertex, ta)
        call triangulate(b%vertex, tb)
        do i = 1, size(ta, 3)
            do j = 1, size(tb, 3)
                if (.not. (separated(ta(:, :, i), tb(:, :, j)) .or. separated(tb(:, :, j), ta(:, :, i)))) then
                    overlap = .true.
                    return
                end if
            end do
        end do
    contains
        !> Whether an edge normal of triangle p separates p and q (gap > -tol).
        pure logical function separated(p, q)
            real(wp), intent(in) :: p(2, 3), q(2, 3)
            real(wp) :: n(2), lp, hp, lq, hq
            integer :: k
            separated = .false.
            do k = 1, 3
                n = p(:, modulo(k, 3) + 1) - p(:, k)
                n = [-n(2), n(1)]/norm2(n)
                lp = minval(matmul(n, p))
                hp = maxval(matmul(n, p))
                lq = minval(matmul(n, q))
                hq = maxval(matmul(n, q))
                if (lp >= hq - tol .or. lq >= hp - tol) then
                    separated = .true.
                    return
                end if
            end do
        end function separated
    end function regions_overlap

    !> Triangles (2, 3, n_triangles) of a simple polygon by ear clipping, counter-clockwise;
    !> vertices on a straight line between their neighbours are dropped (no zero-area triangle).
    pure subroutine triangulate(vertex, tri)
        !> Vertices (2, n), either orientation.
        real(wp), intent(in) :: vertex(:, :)
        !> The triangles.
        real(wp), allocatable, intent(out) :: tri(:, :, :)
        real(wp), allocatable :: v(:, :)
        real(wp) :: area, turn
        integer :: n, m, k, i, prev, next, j
        logical :: ear
        n = size(vertex, 2)
        area = 0.0_wp
        do k = 1, n
            area = area + cross(vertex(:, k), vertex(:, modulo(k, n) + 1))
        end do
        if (area >= 0.0_wp) then
            v = vertex
        else
            v = vertex(:, n:1:-1)
        end if
        allocate (tri(2, 3, max(n - 2, 0)))
        m = 0
        do while (size(v, 2) >= 3)
            n = size(v, 2)
            ear = .false.
            do i = 1, n
                prev = modulo(i - 2, n) + 1
                next = modulo(i, n) + 1
                turn = cross(v(:, i) - v(:, prev), v(:, next) - v(:, i))
                if (turn == 0.0_wp) then
                    ! on the line through its neighbours: drop it
                    ear = .true.
                    exit
                end if
                if (turn < 0.0_wp) cycle
                ear = .true.
                do j = 1, n
                    if (j == i .or. j == prev .or. j == next) cycle
                    if (in_triangle(v(:, j), v(:, prev), v(:, i), v(:, next))) then
                        ear = .false.
                        exit
                    end if
                end do
                if (ear) then
                    m = m + 1
                    tri(:, :, m) = reshape([v(:, prev), v(:, i), v(:, next)], [2, 3])
                    exit
                end if
            end do
            ! No ear: not a simple polygon; the rest as a fan from its first vertex.
            if (.not. ear) then
                do k = 2, n - 1
                    m = m + 1
                    tri(:, :, m) = reshape([v(:, 1), v(:, k), v(:, k + 1)], [2, 3])
                end do
                exit
            end if
            v = v(:, pack([(k, k=1, n)], [(k /= i, k=1, n)]))
        end do
        tri = tri(:, :, :m)
    end subroutine triangulate

    !> Whether p lies in the counter-clockwise triangle (a, b, c), its boundary included.
    pure logical function in_triangle(p, a, b, c)
        real(wp), intent(in) :: p(2), a(2), b(2), c(2)
        in_triangle = cross(b - a, p - a) >= 0.0_wp .and. cross(c - b, p - b) >= 0.0_wp .and. &
                      cross(a - c, p - c) >= 0.0_wp
    end function in_triangle

    !> z component of a x b.
    pure real(wp) function cross(a, b)
        real(wp), intent(in) :: a(2), b(2)
        cross = a(1)*b(2) - a(2)*b(1)
    end function cross

    !> Distance from p to the segment [a, b].
    pure real(wp) function segment_distance(p, a, b) result(d)
        real(wp), intent(in) :: p(2), a(2), b(2)
        real(wp) :: t, ab(2)
        ab = b - a
        t = max(0.0_wp, min(1.0_wp, dot_product(p - a, ab)/dot_product(ab, ab)))
        d = norm2(p - a - t*ab)
    end function segment_distance

    !> 1 for a point of the region (boundary included), 0 outside.
    pure integer function overlap_region_of(self, x, y) result(k)
        !> The region.
        class(overlap2d_t), intent(in) :: self
        !> The point [m].
        real(wp), intent(in) :: x, y
        k = merge(1, 0, self%contains(x, y))
    end function overlap_region_of

    !> Inside test (crossing number), the boundary included.
    pure logical function overlap_contains(self, x, y) result(inside)
        !> The region.
        class(overlap2d_t), intent(in) :: self
        !> The point [m].
        real(wp), intent(in) :: x, y
        integer :: k, n
        real(wp) :: a(2), b(2)
        inside = .false.
        if (x < self%box(1) - self%tol .or. x > self%box(2) + self%tol .or. &
            y < self%box(3) - self%tol .or. y > self%box(4) + self%tol) return
        n = size(self%vertex, 2)
        do k = 1, n
            a = self%vertex(:, k)
            b = self%vertex(:, modulo(k, n) + 1)
            if (segment_distance([x, y], a, b) <= self%tol) then
                inside = .true.
                return
            end if
            if ((a(2) > y) .neqv. (b(2) > y)) then
                if (x < a(1) + (y - a(2))*(b(1) - a(1))/(b(2) - a(2))) inside = .not. inside
            end if
        end do
    end function overlap_contains

    !> xi = d_fe/(d_fe + d_p) of a point of the region (0 for the constant shape without tags).
    pure real(wp) function overlap_reduced(self, x, y) result(xi)
        !> The region.
        class(overlap2d_t), intent(in) :: self
        !> The point [m].
        real(wp), intent(in) :: x, y
        real(wp) :: dfe, dp, d
        integer :: k, n
        n = size(self%vertex, 2)
        dfe = huge(1.0_wp)
        dp = huge(1.0_wp)
        do k = 1, n
            if (.not. (self%fe_edge(k) .or. self%particle_edge(k))) cycle
            d = segment_distance([x, y], self%vertex(:, k), self%vertex(:, modulo(k, n) + 1))
            if (self%fe_edge(k)) dfe = min(dfe, d)
            if (self%particle_edge(k)) dp = min(dp, d)
        end do
        if (dfe == huge(1.0_wp) .or. dp == huge(1.0_wp)) then
            xi = 0.0_wp
        else if (dfe + dp > 0) then
            xi = dfe/(dfe + dp)
        else
            xi = 0.0_wp
        end if
    end function overlap_reduced

    !> FE weight: the clipped ramp in the region, 1 outside (FE-only zone).
    pure real(wp) function overlap_alpha_fe(self, x, y) result(alpha)
        !> The region.
        class(overlap2d_t), intent(in) :: self
        !> The point [m].
        real(wp), intent(in) :: x, y
        if (self%contains(x, y)) then
            alpha = self%weight%value(self%reduced(x, y))
        else
            alpha = 1.0_wp
        end if
    end function overlap_alpha_fe

    !> Disk weight alpha: the clipped ramp in the region, 0 outside (particle-only zone).
    pure real(wp) function overlap_alpha_disk(self, x, y) result(alpha)
        !> The region.
        class(overlap2d_t), intent(in) :: self
        !> The point [m].
        real(wp), intent(in) :: x, y
        if (self%contains(x, y)) then
            alpha = self%weight%value(self%reduced(x, y))
        else
            alpha = 0.0_wp
        end if
    end function overlap_alpha_disk

    !> Disk weights alpha_disk at the centres and the disks to couple: those with alpha > 0
    !> (centre in the overlap), in increasing order.
    pure subroutine field_select_disks(self, x, y, coupled, alpha)
        !> The weight field.
        class(weight_field_t), intent(in) :: self
        !> Disk centres [m] (n_disks each).
        real(wp), intent(in) :: x(:), y(:)
        !> Indices of the coupled disks.
        integer, allocatable, intent(out) :: coupled(:)
        !> alpha of every disk (n_disks); its weighted mass is (1 - alpha) m.
        real(wp), allocatable, intent(out) :: alpha(:)
        integer :: i
        allocate (alpha(size(x)))
        do i = 1, size(x)
            alpha(i) = self%alpha_disk(x(i), y(i))
        end do
        coupled = pack([(i, i=1, size(x))], alpha > 0)
    end subroutine field_select_disks

    !> True when the box misses the region's bounding box (up to the boundary tolerance).
    pure logical function overlap_misses(self, box)
        !> The region.
        class(overlap2d_t), intent(in) :: self
        !> The box (xmin, xmax, ymin, ymax) [m].
        real(wp), intent(in) :: box(4)
        overlap_misses = box(2) < self%box(1) - self%tol .or. box(1) > self%box(2) + self%tol .or. &
                         box(4) < self%box(3) - self%tol .or. box(3) > self%box(4) + self%tol
    end function overlap_misses

    !> FE weight of the first region holding the point, 1 outside all.
    pure real(wp) function set_alpha_fe(self, x, y) result(alpha)
        !> The regions.
        class(overlap_set_t), intent(in) :: self
        !> The point [m].
        real(wp), intent(in) :: x, y
        integer :: k
        alpha = 1.0_wp
        do k = 1, size(self%regions)
            if (.not. self%regions(k)%contains(x, y)) cycle
            alpha = self%regions(k)%alpha_fe(x, y)
            return
        end do
    end function set_alpha_fe

    !> Disk weight of the first region holding the point, 0 outside all.
    pure real(wp) function set_alpha_disk(self, x, y) result(alpha)
        !> The regions.
        class(overlap_set_t), intent(in) :: self
        !> The point [m].
        real(wp), intent(in) :: x, y
        integer :: k
        alpha = 0.0_wp
        do k = 1, size(self%regions)
            if (.not. self%regions(k)%contains(x, y)) cycle
            alpha = self%regions(k)%alpha_disk(x, y)
            return
        end do
    end function set_alpha_disk

    !> Number of the first region holding the point (0: none).
    pure integer function set_region_of(self, x, y) result(k)
        !> The regions.
        class(overlap_set_t), intent(in) :: self
        !> The point [m].
        real(wp), intent(in) :: x, y
        do k = 1, size(self%regions)
            if (self%regions(k)%contains(x, y)) return
        end do
        k = 0
    end function set_region_of

    !> True when the box misses every region.
    pure logical function set_misses(self, box)
        !> The regions.
        class(overlap_set_t), intent(in) :: self
        !> The box (xmin, xmax, ymin, ymax) [m].
        real(wp), intent(in) :: box(4)
        integer :: k
        set_misses = .true.
        do k = 1, size(self%regions)
            if (.not. self%regions(k)%misses(box)) set_misses = .false.
        end do
    end function set_misses

    !> The region's ramp and floor.
    pure function overlap_ramp(self) result(ramp)
        !> The region.
        class(overlap2d_t), intent(in) :: self
        !> Its ramp.
        type(overlap_weight_t) :: ramp
        ramp = self%weight
    end function overlap_ramp

    !> The ramp of the first region (a set's regions share the deck's weight); the default
    !> ramp for an empty set.
    pure function set_ramp(self) result(ramp)
        !> The regions.
        class(overlap_set_t), intent(in) :: self
        !> The ramp.
        type(overlap_weight_t) :: ramp
        if (size(self%regions) > 0) ramp = self%regions(1)%weight
    end function set_ramp

    !> Probes at 9 points along each particle-side edge (at tenths of its length), just outside
    !> the region (beyond its boundary tolerance), on the side of the edge away from the
    !> region; a point that falls in the region on both sides is left out. In edge order.
    pure subroutine overlap_particle_side_probes(self, q, edge, region)
        !> The region.
        class(overlap2d_t), intent(in) :: self
        !> The points (2, n_probes) [m].
        real(wp), allocatable, intent(out) :: q(:, :)
        !> Edge of each point (n_probes).
        integer, allocatable, intent(out) :: edge(:)
        !> 0 for each point (a single region).
        integer, allocatable, intent(out) :: region(:)
        real(wp) :: a(2), b(2), t(2), normal(2), p(2), r(2), length, offset
        integer :: k, n, j, m
        n = size(self%vertex, 2)
        allocate (q(2, 9*count(self%particle_edge)), edge(9*count(self%particle_edge)))
        m = 0
        do k = 1, n
            if (.not. self%particle_edge(k)) cycle
            a = self%vertex(:, k)
            b = self%vertex(:, modulo(k, n) + 1)
            length = norm2(b - a)
            if (.not. (length > 0)) cycle
            t = (b - a)/length
            normal = [t(2), -t(1)]
            offset = max(4*self%tol, 1.0e-6_wp*length)
            do j = 1, 9
                p = a + (real(j, wp)/10)*(b - a)
                r = p + offset*normal
                if (self%contains(r(1), r(2))) r = p - offset*normal
                if (self%contains(r(1), r(2))) cycle
                m = m + 1
                q(:, m) = r
                edge(m) = k
            end do
        end do
        q = q(:, :m)
        edge = edge(:m)
        allocate (region(m), source=0)
    end subroutine overlap_particle_side_probes

    !> The probes of each region in turn (`overlap2d_t%particle_side_probes`), with its number.
    pure subroutine set_particle_side_probes(self, q, edge, region)
        !> The regions.
        class(overlap_set_t), intent(in) :: self
        !> The points (2, n_probes) [m].
        real(wp), allocatable, intent(out) :: q(:, :)
        !> Edge of each point, in its region (n_probes).
        integer, allocatable, intent(out) :: edge(:)
        !> Region of each point (n_probes).
        integer, allocatable, intent(out) :: region(:)
        real(wp), allocatable :: qr(:, :)
        integer, allocatable :: er(:), unused(:)
        integer :: r
        allocate (q(2, 0), edge(0), region(0))
        do r = 1, size(self%regions)
            call self%regions(r)%particle_side_probes(qr, er, unused)
            q = reshape([q, qr], [2, size(q, 2) + size(qr, 2)])
            edge = [edge, er]
            region = [region, spread(r, 1, size(er))]
        end do
    end subroutine set_particle_side_probes
end module coupling_overlap2d
