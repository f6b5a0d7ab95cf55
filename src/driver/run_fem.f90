!> Placeholder: to be written.
module driver_run_fem
    implicit none
    private
end module driver_run_fem
