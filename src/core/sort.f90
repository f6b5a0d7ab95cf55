!> Sorting of small real arrays in place (breakpoint lists, timing samples), and the
!> permutation that sorts integer keys (deck ids, node pairs), stable, in O(n log n).
module core_sort
    use core_kinds, only: wp, i8
    implicit none
    private
    public :: sort_in_place, sort_index

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

    !> Permutation sorting `keys` in increasing order: keys(order) is non-decreasing, and
    !> equal keys keep their input order (stable; bottom-up merge sort, O(n log n)).
    pure function sort_index(keys) result(order)
        !> Keys.
        integer(i8), intent(in) :: keys(:)
        !> Positions in `keys`, in increasing key order.
        integer, allocatable :: order(:)
        integer, allocatable :: buffer(:)
        integer :: n, width, lo, mid, hi, i, j, k
        n = size(keys)
        order = [(i, i=1, n)]
        allocate (buffer(n))
        width = 1
        do while (width < n)
            do lo = 1, n, 2*width
                mid = min(lo + width, n + 1)
                hi = min(lo + 2*width, n + 1)
                i = lo
                j = mid
                do k = lo, hi - 1
                    ! min() keeps the indices valid: Fortran does not short-circuit .or.
                    if (i < mid .and. (j >= hi .or. &
                                       keys(order(min(i, n))) <= keys(order(min(j, n))))) then
                        buffer(k) = order(i)
                        i = i + 1
                    else
                        buffer(k) = order(j)
                        j = j + 1
                    end if
                end do
            end do
            order = buffer
            width = 2*width
        end do
    end function sort_index
end module core_sort
