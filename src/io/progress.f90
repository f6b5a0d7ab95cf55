!> Placeholder: to be written.
module io_progress
    implicit none
    private
end module io_progress
