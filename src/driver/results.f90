!> Placeholder: to be written.
module driver_results
    implicit none
    private
end module driver_results
