!> Placeholder: to be written.
module fem_newmark
    implicit none
    private
end module fem_newmark
