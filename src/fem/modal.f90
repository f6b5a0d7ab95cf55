!> Placeholder: to be written.
module fem_modal
    implicit none
    private
end module fem_modal
