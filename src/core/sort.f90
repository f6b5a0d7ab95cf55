!> Sorting of small real arrays in place (breakpoint lists, timing samples).
module core_sort
    use core_kinds, only: wp
    implicit none
    private
    public :: sort_in_place

contains

    !> Sort a real array into ascending order, in place (insertion sort: stable, meant for
    !> the short arrays it is used on; equal values are all kept).
    pure subroutine sort_in_place(a)
        !> Values to sort; on return in ascending order.
        real(wp), intent(inout) :: a(:)
        real(wp) :: key
        integer :: i, j
        do i = 2, size(a)
            key = a(i)
            j = i - 1
            do while (j >= 1)
                if (a(j) <= key) exit
                a(j + 1) = a(j)
                j = j - 1
            end do
            a(j + 1) = key
        end do
    end subroutine sort_in_place
end module core_sort
