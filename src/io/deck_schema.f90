!> Placeholder: to be written.
module io_deck_schema
    implicit none
    private
end module io_deck_schema
