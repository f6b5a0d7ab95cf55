!> Small deterministic pseudo-random generator (Marsaglia's xorshift64) for the particle
!> generators and the tests. Same sequence on every compiler for a given seed; only shifts
!> and exclusive-or are used, so no integer overflow can occur. The state lives in the caller's
!> `rng_t` (no module state).
module dem_random
    use core_kinds, only: wp, i8
    implicit none
    private
    public :: rng_t, rng_seed, rng_uniform, rng_uniform_in

    !> Generator state (never zero).
    type :: rng_t
        !> 64-bit state.
        integer(i8) :: state = 88172645463325252_i8
    end type rng_t

contains

    !> Seed the generator; equal seeds give equal sequences.
    pure subroutine rng_seed(rng, seed)
        !> Generator to seed.
        type(rng_t), intent(inout) :: rng
        !> Any integer.
        integer, intent(in) :: seed
        real(wp) :: discard
        integer :: k
        rng%state = ieor(88172645463325252_i8, ishft(int(seed, i8), 17) + int(seed, i8))
        if (rng%state == 0_i8) rng%state = 88172645463325252_i8
        ! decorrelate nearby seeds
        do k = 1, 16
            call rng_uniform(rng, discard)
        end do
    end subroutine rng_seed

    !> Next number, uniform in [0, 1), with 53 random bits.
    pure subroutine rng_uniform(rng, u)
        !> Generator.
        type(rng_t), intent(inout) :: rng
        !> Uniform deviate in [0, 1).
        real(wp), intent(out) :: u
        integer(i8) :: s
        s = rng%state
        s = ieor(s, ishft(s, 13))
        s = ieor(s, ishft(s, -7))
        s = ieor(s, ishft(s, 17))
        rng%state = s
        u = real(ishft(s, -11), wp)*2.0_wp**(-53)
    end subroutine rng_uniform

    !> Next number, uniform in [a, b).
    pure subroutine rng_uniform_in(rng, a, b, u)
        !> Generator.
        type(rng_t), intent(inout) :: rng
        !> Lower bound.
        real(wp), intent(in) :: a
        !> Upper bound.
        real(wp), intent(in) :: b
        !> Uniform deviate in [a, b).
        real(wp), intent(out) :: u
        call rng_uniform(rng, u)
        u = a + (b - a)*u
    end subroutine rng_uniform_in
end module dem_random
