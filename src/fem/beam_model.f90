!> Placeholder: to be written.
module fem_beam_model
    implicit none
    private
end module fem_beam_model
