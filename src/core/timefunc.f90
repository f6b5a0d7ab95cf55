!> Time functions f(t) that multiply loads, imposed velocities and wall velocities
!> ([functions] of the deck), as a family: the abstract `time_function_t` asks each kind for
!> its value, rate, acceleration and whether it vanishes on an interval; each kind is an
!> extension in its own module (core_timefunc_constant, core_timefunc_ramp,
!> core_timefunc_step, core_timefunc_table, core_timefunc_harmonic), built from the deck by
!> driver_config_timefunc. A new kind is a new module and one deck word there.
!>
!> The models keep their functions in an array of slots (`time_function_slot_t`), each holding
!> one function of any kind, in the order of the deck's records. Evaluation is not in a hot
!> loop (once per load, drive or function per step).
module core_timefunc
    use core_kinds, only: wp
    implicit none
    private
    public :: time_function_t, time_function_slot_t

    !> A time function f(t) (dimensionless; t in s).
    type, abstract :: time_function_t
    contains
        !> Value at time t.
        procedure(value_iface), deferred :: value
        !> Rate df/dt at time t (right derivative at a kink).
        procedure(value_iface), deferred :: rate
        !> Second derivative d2f/dt2 at time t (the impulses at kinks and jumps are not
        !> represented).
        procedure(value_iface), deferred :: acceleration
        !> Whether f(t) = 0 at every t of a closed interval [t0, t1].
        procedure(zero_on_iface), deferred :: zero_on
    end type time_function_t

    abstract interface
        !> f(t), df/dt [1/s] or d2f/dt2 [1/s^2] at time t.
        pure real(wp) function value_iface(self, t) result(f)
            import :: time_function_t, wp
            !> The function.
            class(time_function_t), intent(in) :: self
            !> Time [s].
            real(wp), intent(in) :: t
        end function value_iface

        !> Whether f(t) = 0 at every t of [t0, t1], exact for f as `value` computes it; true
        !> for an empty interval (t1 < t0).
        pure logical function zero_on_iface(self, t0, t1) result(zero)
            import :: time_function_t, wp
            !> The function.
            class(time_function_t), intent(in) :: self
            !> Start and end of the interval [s].
            real(wp), intent(in) :: t0, t1
        end function zero_on_iface
    end interface

    !> One time function of any kind, so that a model can keep an array of them.
    type :: time_function_slot_t
        !> The function (allocated by the deck reader, or by a test).
        class(time_function_t), allocatable :: fn
    end type time_function_slot_t
end module core_timefunc
