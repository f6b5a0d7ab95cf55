!> Abstract weight function alpha(s) of the Arlequin energy partition (doc/theory.md section 6.1),
!> s being the curvilinear abscissa along the beam axis.
!>
!> Only the interface lives here, so that the FE assembly (fem) can integrate with a weight
!> without depending on the coupling package, which holds the concrete weights.
module core_weight
    use core_kinds, only: wp
    implicit none
    private
    public :: weight_function_t

    !> A weight alpha(s) in [0, 1] along the beam: 1 where only the FE model carries the
    !> energy, 0 where only the particles do.
    type, abstract :: weight_function_t
    contains
        !> alpha(s).
        procedure(weight_value), deferred :: value
        !> Abscissas where alpha or its derivatives jump (quadrature splits there).
        procedure(weight_breakpoints), deferred :: breakpoints
    end type weight_function_t

    abstract interface
        !> Weight alpha at abscissa s.
        pure real(wp) function weight_value(self, s)
            import :: weight_function_t, wp
            !> The weight function.
            class(weight_function_t), intent(in) :: self
            !> Curvilinear abscissa along the beam axis [m].
            real(wp), intent(in) :: s
        end function weight_value

        !> Abscissas [m] where alpha is not smooth (ends of the overlap, kinks of a floor), in
        !> increasing order (empty for a smooth weight): a piecewise polynomial weight is
        !> integrated exactly by Gauss quadrature on the pieces between them.
        pure function weight_breakpoints(self) result(s)
            import :: weight_function_t, wp
            !> The weight function.
            class(weight_function_t), intent(in) :: self
            real(wp), allocatable :: s(:)
        end function weight_breakpoints
    end interface

end module core_weight
