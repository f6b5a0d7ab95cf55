!> Placeholder: to be written.
module fem_static
    implicit none
    private
end module fem_static
