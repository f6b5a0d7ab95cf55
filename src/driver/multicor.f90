!> Placeholder driver.
program multicor
    implicit none
end program multicor
