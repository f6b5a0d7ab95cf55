!> Placeholder: to be written.
module core_strings
    implicit none
    private
end module core_strings
