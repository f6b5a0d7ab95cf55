!> Placeholder: to be written.
module fem_beam_element
    implicit none
    private
end module fem_beam_element
