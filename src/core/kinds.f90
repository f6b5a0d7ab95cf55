!> Working precision and other kind parameters used everywhere in MULTICOR.
module core_kinds
    use, intrinsic :: iso_fortran_env, only: real64, int32, int64
    implicit none
    private
    public :: wp, ip, i8

    !> Working real precision (IEEE double).
    integer, parameter :: wp = real64
    !> Default integer kind for indices.
    integer, parameter :: ip = int32
    !> Long integer kind (counters, byte counts).
    integer, parameter :: i8 = int64
end module core_kinds
