!> Checks of text a user typed (a deck, the names of a mesh) against UTF-8: the first byte
!> that is not UTF-8 (a file saved as Latin-1 or Windows-1252: `é` is the single byte 0xE9),
!> and the invisible Unicode spaces that an editor shows as a blank but that do not separate
!> words (a no-break space typed with AltGr+Space, a thin space pasted from a document).
!> Columns are counted in bytes, as the other messages of the deck reader count them.
module core_utf8
    implicit none
    private
    public :: invalid_utf8_column, find_invisible_space, byte_hex, replace_invalid_utf8, printable

    !> An invisible Unicode space: its code point and its Unicode name.
    type :: invisible_t
        !> Code point.
        integer :: code = 0
        !> Unicode name, lowercase.
        character(len=48) :: name = ''
    end type invisible_t

    !> The spaces that look like a blank (or like nothing) in an editor: no-break, typographic,
    !> zero width and ideographic spaces, the word joiner and a byte-order mark inside the text
    !> (the one at the start of a file is the reader's to skip).
    type(invisible_t), parameter :: invisible(17) = [ &
                                    invisible_t(int(z'00A0'), 'no-break space'), &
                                    invisible_t(int(z'2000'), 'en quad'), &
                                    invisible_t(int(z'2001'), 'em quad'), &
                                    invisible_t(int(z'2002'), 'en space'), &
                                    invisible_t(int(z'2003'), 'em space'), &
                                    invisible_t(int(z'2004'), 'three-per-em space'), &
                                    invisible_t(int(z'2005'), 'four-per-em space'), &
                                    invisible_t(int(z'2006'), 'six-per-em space'), &
                                    invisible_t(int(z'2007'), 'figure space'), &
                                    invisible_t(int(z'2008'), 'punctuation space'), &
                                    invisible_t(int(z'2009'), 'thin space'), &
                                    invisible_t(int(z'200A'), 'hair space'), &
                                    invisible_t(int(z'200B'), 'zero width space'), &
                                    invisible_t(int(z'202F'), 'narrow no-break space'), &
                                    invisible_t(int(z'2060'), 'word joiner'), &
                                    invisible_t(int(z'3000'), 'ideographic space'), &
                                    invisible_t(int(z'FEFF'), 'byte-order mark, zero width no-break space')]

contains

    !> Column (in bytes) of the first byte of `text` that does not begin or continue a
    !> well-formed UTF-8 sequence (RFC 3629: no overlong form, no surrogate, nothing beyond
    !> U+10FFFF); 0 when the text is UTF-8 throughout.
    pure integer function invalid_utf8_column(text) result(column)
        !> The text.
        character(len=*), intent(in) :: text
        integer :: i, n
        i = 1
        do while (i <= len(text))
            n = sequence_length(text, i)
            if (n == 0) then
                column = i
                return
            end if
            i = i + n
        end do
        column = 0
    end function invalid_utf8_column

    !> Column (in bytes) of the first invisible Unicode space of `text` (a no-break, thin,
    !> narrow no-break or zero width space, ...; 0 when there is none), with its Unicode name
    !> and code point in `what`. Bytes that are not UTF-8 are passed over.
    pure subroutine find_invisible_space(text, column, what)
        !> The text.
        character(len=*), intent(in) :: text
        !> Column of the first byte of the space (0: none).
        integer, intent(out) :: column
        !> "no-break space (U+00A0)" for the space found ('' when none).
        character(len=:), allocatable, intent(out) :: what
        integer :: i, n, code, k
        character(len=4) :: hex
        what = ''
        i = 1
        do while (i <= len(text))
            n = sequence_length(text, i)
            if (n < 2) then
                i = i + 1
                cycle
            end if
            code = code_point(text(i:i + n - 1))
            write (hex, '(z4.4)') code
            do k = 1, size(invisible)
                if (invisible(k)%code /= code) cycle
                what = trim(invisible(k)%name)//' (U+'//hex//')'
                column = i
                return
            end do
            i = i + n
        end do
        column = 0
    end subroutine find_invisible_space

    !> `text` with each byte that does not begin or continue a well-formed UTF-8 sequence
    !> replaced by the replacement character U+FFFD (three bytes, shown as a question mark in
    !> a box): text that may be stored as UTF-8 (the deck in the results); `text` itself when
    !> it is UTF-8 throughout.
    pure function replace_invalid_utf8(text) result(utf8)
        !> The text.
        character(len=*), intent(in) :: text
        character(len=:), allocatable :: utf8
        character(len=*), parameter :: replacement = char(int(z'EF'))//char(int(z'BF'))//char(int(z'BD'))
        integer :: i, n, k, first
        first = invalid_utf8_column(text)
        if (first == 0) then
            utf8 = text
            return
        end if
        ! at most three bytes for each byte of the text
        allocate (character(len=3*len(text)) :: utf8)
        utf8(:first - 1) = text(:first - 1)
        k = first - 1
        i = first
        do while (i <= len(text))
            n = sequence_length(text, i)
            if (n == 0) then
                utf8(k + 1:k + 3) = replacement
                k = k + 3
                i = i + 1
            else
                utf8(k + 1:k + n) = text(i:i + n - 1)
                k = k + n
                i = i + n
            end if
        end do
        utf8 = utf8(:k)
    end function replace_invalid_utf8

    !> `text` as a message may show it on a terminal: each control character (a byte below 32,
    !> or 127: a NUL, an escape sequence) and each byte that does not begin or continue a
    !> well-formed UTF-8 sequence written as its value between angle brackets (`<0x00>`, `<0xFF>`,
    !> as the deck reader names such bytes); `text` itself when it has none. A file of junk
    !> echoed in a message (`found "<0x00><0x01>junk<0xFF>"`) then prints as text.
    pure function printable(text) result(shown)
        !> The text.
        character(len=*), intent(in) :: text
        character(len=:), allocatable :: shown
        integer :: i, n, k
        i = 1
        do while (i <= len(text))
            n = shown_length(i)
            if (n == 0) exit
            i = i + n
        end do
        if (i > len(text)) then
            shown = text
            return
        end if
        ! at most six bytes for each byte of the text
        allocate (character(len=6*len(text)) :: shown)
        shown(:i - 1) = text(:i - 1)
        k = i - 1
        do while (i <= len(text))
            n = shown_length(i)
            if (n == 0) then
                shown(k + 1:k + 6) = '<'//byte_hex(text(i:i))//'>'
                k = k + 6
                i = i + 1
            else
                shown(k + 1:k + n) = text(i:i + n - 1)
                k = k + n
                i = i + n
            end if
        end do
        shown = shown(:k)
    contains
        !> Length of the UTF-8 sequence at byte j that is shown as it is; 0 for a byte to escape.
        pure integer function shown_length(j) result(m)
            integer, intent(in) :: j
            integer :: c
            m = sequence_length(text, j)
            c = ichar(text(j:j))
            if (m == 1 .and. (c < 32 .or. c == 127)) m = 0
        end function shown_length
    end function printable

    !> A byte as `0xE9`.
    pure function byte_hex(c) result(text)
        !> The byte.
        character(len=1), intent(in) :: c
        character(len=4) :: text
        write (text, '(a,z2.2)') '0x', ichar(c)
    end function byte_hex

    !> Length of the well-formed UTF-8 sequence starting at byte i of text (1 to 4), 0 when
    !> the bytes there are not one.
    pure integer function sequence_length(text, i) result(n)
        character(len=*), intent(in) :: text
        integer, intent(in) :: i
        integer :: lead, lo, hi, k, c
        lead = ichar(text(i:i))
        lo = 128
        hi = 191
        select case (lead)
        case (0:127)
            n = 1
            return
        case (194:223)
            n = 2
        case (224)
            n = 3
            lo = 160
        case (225:236, 238:239)
            n = 3
        case (237)
            n = 3
            hi = 159
        case (240)
            n = 4
            lo = 144
        case (241:243)
            n = 4
        case (244)
            n = 4
            hi = 143
        case default
            n = 0
            return
        end select
        if (i + n - 1 > len(text)) then
            n = 0
            return
        end if
        do k = 1, n - 1
            c = ichar(text(i + k:i + k))
            if (k > 1) then
                lo = 128
                hi = 191
            end if
            if (c < lo .or. c > hi) then
                n = 0
                return
            end if
        end do
    end function sequence_length

    !> Code point of one well-formed UTF-8 sequence of 2 to 4 bytes.
    pure integer function code_point(bytes) result(code)
        character(len=*), intent(in) :: bytes
        integer :: k
        select case (len(bytes))
        case (2)
            code = iand(ichar(bytes(1:1)), int(z'1F'))
        case (3)
            code = iand(ichar(bytes(1:1)), int(z'0F'))
        case default
            code = iand(ichar(bytes(1:1)), int(z'07'))
        end select
        do k = 2, len(bytes)
            code = ior(ishft(code, 6), iand(ichar(bytes(k:k)), int(z'3F')))
        end do
    end function code_point
end module core_utf8
