!> Projection of a point on the axis of a planar beam (doc/theory.md section 6.3): the nearest
!> point of the beam's polyline, each element a segment, the polyline continued straight past
!> its ends (a node of a single element). The one projection of the coupling: the weight
!> alpha of a disk, the choice of the coupled disks, the interpolation C and the stored
!> abscissa and offset all come from it.
!>
!> Per element, the point (px, py) has the reduced coordinate xi = ((p - x1) . t) / L along
!> it and the signed distance o = (p - x1) . n across it (n = (-sin, cos), on the left).
!> The nearest point of the element is at xi clamped to [0, 1], except past an end of the
!> beam, where xi runs on along the element's line. A point projecting within 1e-10 L past a
!> joint (a point placed on a node, up to rounding) is on the element: its xi is clamped to
!> the node, its abscissa is that of its projection on the element's line, which differs
!> from the node's by that rounding only (so that the abscissa does not jump by a rounding
!> error where a point crosses a node).
!> The arm from that nearest point to the point has the components (along, across) in the
!> element's axes: (0, o) when the point projects onto the element, (xi - 1) L or xi L along
!> and o across when it lies beyond a joint of the element (a point in the outer corner of a
!> bend, whose nearest point of the polyline is the joint node itself).
!>
!> The element kept is the one nearest to the point as a segment (its distance to the point
!> with xi clamped to [0, 1]: the continuation past a free end is not counted in the choice,
!> so that the line continued from one cantilever's end never takes a point that lies beside
!> another element); on a tie (distances within 1e-10 of the element's length: two elements
!> meeting at the node nearest to the point, or a point equidistant from two branches) the
!> lower element index. A point beyond a bend has the abscissa of the bend's node whichever
!> element holds it.
module fem_beam_projection
    use core_kinds, only: wp
    use fem_beam_model, only: beam_model_t
    implicit none
    private
    public :: beam_point_t, project_on_beam

    ! Relative tolerance of the projection (fractions of the element's length): a projection
    ! this close past a joint is on the element; arms this close in length are a tie.
    real(wp), parameter :: snap = 1.0e-10_wp

    !> Where a point sits relative to the beam: its nearest point on the axis and the rigid
    !> arm from there to the point.
    type :: beam_point_t
        !> Element holding the nearest point (0 when the beam has no element).
        integer :: element = 0
        !> Reduced coordinate of the nearest point on that element: in [0, 1], or past 0 or 1
        !> on the continuation of the element past an end of the beam.
        real(wp) :: xi = 0.0_wp
        !> Curvilinear abscissa of the nearest point [m] (linear in xi, also past an end; for a
        !> point within 1e-10 L past a joint, that of its projection on the element's line).
        real(wp) :: abscissa = 0.0_wp
        !> Component of the arm along the element [m] (0 unless the point lies beyond a joint
        !> of the element).
        real(wp) :: along = 0.0_wp
        !> Component of the arm across the element [m], positive on the left of its direction.
        real(wp) :: across = 0.0_wp
    contains
        !> Signed distance of the point from the beam axis [m].
        procedure :: offset
        !> Whether the nearest point lies past an end of the beam (not on an element).
        procedure :: past_end
    end type beam_point_t

contains

    !> The projection of (px, py) on the beam's axis (see the module description).
    pure function project_on_beam(model, px, py) result(point)
        !> The beam model.
        type(beam_model_t), intent(in) :: model
        !> Coordinates of the point [m].
        real(wp), intent(in) :: px, py
        !> The nearest point on the axis and the arm to the point.
        type(beam_point_t) :: point
        integer :: uses(model%n_nodes)
        integer :: e, n1, n2
        real(wp) :: dx, dy, xi, xc, xs, along, across, d, d_best
        uses = 0
        do e = 1, model%n_elements
            uses(model%conn(:, e)) = uses(model%conn(:, e)) + 1
        end do
        d_best = huge(1.0_wp)
        do e = 1, model%n_elements
            n1 = model%conn(1, e)
            n2 = model%conn(2, e)
            dx = px - model%x(n1)
            dy = py - model%y(n1)
            xi = (dx*model%cosine(e) + dy*model%sine(e))/model%length(e)
            across = -dx*model%sine(e) + dy*model%cosine(e)
            along = 0.0_wp
            ! xc: the nearest point for C; xs: for the abscissa (xi itself within the snap)
            if (xi >= -snap .and. xi <= 1 + snap) then
                xc = min(max(xi, 0.0_wp), 1.0_wp)
                xs = xi
            else if ((xi < 0 .and. uses(n1) == 1) .or. (xi > 1 .and. uses(n2) == 1)) then
                xc = xi
                xs = xi
            else
                xc = min(max(xi, 0.0_wp), 1.0_wp)
                xs = xc
                along = (xi - xc)*model%length(e)
            end if
            ! distance to the element as a segment (also past a free end)
            d = hypot((xi - min(max(xi, 0.0_wp), 1.0_wp))*model%length(e), across)
            if (.not. d < d_best - snap*model%length(e)) cycle
            d_best = d
            point%element = e
            point%xi = xc
            point%abscissa = model%abscissa_at(e, xs)
            point%along = along
            point%across = across
        end do
    end function project_on_beam

    !> Signed distance from the axis [m]: the length of the arm, with the sign of its across
    !> component (positive when that is zero, for a point beyond a joint on the element's line).
    pure real(wp) function offset(self)
        !> The projected point.
        class(beam_point_t), intent(in) :: self
        offset = sign(hypot(self%along, self%across), self%across)
    end function offset

    !> Whether the nearest point lies past an end of the beam, on the continuation of its end
    !> element (xi outside [0, 1]): the beam does not reach the point.
    pure logical function past_end(self)
        !> The projected point.
        class(beam_point_t), intent(in) :: self
        past_end = self%xi < 0 .or. self%xi > 1
    end function past_end
end module fem_beam_projection
