!> Placeholder: to be written.
module core_linalg
    implicit none
    private
end module core_linalg
