!> String utilities for input parsing and messages: case folding, whitespace trimming and
!> splitting (tabs count as blanks), Levenshtein distance and closest-name lookup, strict
!> number parsing that reports bad input instead of crashing, and number formatting.
module core_strings
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use core_kinds, only: wp, i8
    implicit none
    private
    public :: string_t, to_lower, strip, is_blank_char, split_words, split_lines, join_words
    public :: levenshtein, closest_match, parse_real, parse_int, to_str, shorten, max_echo, is_real_syntax
    public :: gib, counted, sci_to_str, sci_text, quoted_name, same_name, shell_word

    !> Longest token echoed whole in a message (see `shorten`).
    integer, parameter :: max_echo = 40

    !> A string of any length, for arrays of strings of different lengths.
    type :: string_t
        !> The characters.
        character(len=:), allocatable :: s
    end type string_t

    !> Text form of a number for messages: integers with `i0`; reals rounded to at most
    !> `max_digits` significant digits, in the shortest form (`0.5`, `2.1e11`, `1e-9`), so that
    !> rounding noise never shows (`0.0019999999999999996` prints `0.002`).
    interface to_str
        module procedure int_to_str, int8_to_str, real_to_str
    end interface to_str

    !> A count with its noun, singular for one: `counted(1, 'disk')` is '1 disk',
    !> `counted(3, 'disk')` '3 disks'.
    interface counted
        module procedure int_counted, int8_counted
    end interface counted

    character(len=*), parameter :: digits = '0123456789'
    !> Significant digits kept by `to_str` for reals: well above what a deck value needs, well
    !> below the 15-17 digits where the rounding of a computation (Debug or Release) shows.
    integer, parameter :: max_digits = 10

contains

    !> Lowercase copy of a string (ASCII letters only).
    pure function to_lower(text) result(lower)
        !> Text to convert.
        character(len=*), intent(in) :: text
        character(len=len(text)) :: lower
        integer :: i, c
        lower = text
        do i = 1, len(text)
            c = iachar(text(i:i))
            if (c >= iachar('A') .and. c <= iachar('Z')) lower(i:i) = achar(c + 32)
        end do
    end function to_lower

    !> True for blank characters: space, tab, carriage return, line feed, form feed.
    elemental logical function is_blank_char(c)
        !> One character.
        character(len=1), intent(in) :: c
        is_blank_char = c == ' ' .or. c == achar(9) .or. c == achar(13) .or. c == achar(10) &
                        .or. c == achar(12)
    end function is_blank_char

    !> Copy of a string without leading and trailing blanks (tabs included).
    pure function strip(text) result(stripped)
        !> Text to strip.
        character(len=*), intent(in) :: text
        character(len=:), allocatable :: stripped
        integer :: first, last
        first = 1
        last = len(text)
        do while (first <= last)
            if (.not. is_blank_char(text(first:first))) exit
            first = first + 1
        end do
        do while (last >= first)
            if (.not. is_blank_char(text(last:last))) exit
            last = last - 1
        end do
        stripped = text(first:last)
    end function strip

    !> Split a string into words separated by blanks (spaces or tabs).
    pure subroutine split_words(text, words)
        !> Text to split.
        character(len=*), intent(in) :: text
        !> The words, in order (size 0 for a blank string).
        type(string_t), allocatable, intent(out) :: words(:)
        integer :: i, start, n
        n = 0
        do i = 1, len(text)
            if (.not. is_blank_char(text(i:i))) then
                if (i == 1) then
                    n = n + 1
                else if (is_blank_char(text(i - 1:i - 1))) then
                    n = n + 1
                end if
            end if
        end do
        allocate (words(n))
        n = 0
        i = 1
        do while (i <= len(text))
            if (is_blank_char(text(i:i))) then
                i = i + 1
                cycle
            end if
            start = i
            do while (i <= len(text))
                if (is_blank_char(text(i:i))) exit
                i = i + 1
            end do
            n = n + 1
            words(n)%s = text(start:i - 1)
        end do
    end subroutine split_words

    !> The lines of a text, each ended by a new_line character (what follows the last one is
    !> not a line): 'a\nb\n' gives 'a' and 'b', '' none, 'a' none.
    pure subroutine split_lines(text, lines)
        !> Text to split.
        character(len=*), intent(in) :: text
        !> The lines, without their new_line, in order.
        type(string_t), allocatable, intent(out) :: lines(:)
        integer :: i, start, n
        allocate (lines(count([(text(i:i) == new_line('a'), i=1, len(text))])))
        n = 0
        start = 1
        do i = 1, len(text)
            if (text(i:i) /= new_line('a')) cycle
            n = n + 1
            lines(n)%s = text(start:i - 1)
            start = i + 1
        end do
    end subroutine split_lines

    !> A name as a deck writes it, for messages: as is, or between double quotes when it holds
    !> a blank or a '#' (`left` stays `left`, `left edge` becomes `"left edge"`).
    pure function quoted_name(name) result(text)
        !> The name.
        character(len=*), intent(in) :: name
        character(len=:), allocatable :: text
        integer :: i
        if (len(name) == 0 .or. any([(is_blank_char(name(i:i)), i=1, len(name))]) .or. index(name, '#') > 0) then
            text = '"'//name//'"'
        else
            text = name
        end if
    end function quoted_name

    !> Whether two names are the same string, of the same length: Fortran's `==` pads the
    !> shorter operand with blanks, so that `'a' == 'a '` holds; names compare exactly.
    pure logical function same_name(a, b)
        !> A name.
        character(len=*), intent(in) :: a
        !> The other name.
        character(len=*), intent(in) :: b
        same_name = len(a) == len(b)
        if (same_name) same_name = a == b
    end function same_name

    !> Join words with a separator: `join_words(['a','b'], ', ')` is `'a, b'`.
    pure function join_words(words, separator) result(joined)
        !> Words to join.
        type(string_t), intent(in) :: words(:)
        !> Text placed between consecutive words.
        character(len=*), intent(in) :: separator
        character(len=:), allocatable :: joined
        integer :: i
        joined = ''
        do i = 1, size(words)
            if (i > 1) joined = joined//separator
            joined = joined//words(i)%s
        end do
    end function join_words

    !> Levenshtein (edit) distance: the least number of single-character insertions,
    !> deletions and substitutions turning `a` into `b`. Case-sensitive.
    pure integer function levenshtein(a, b) result(distance)
        !> First string.
        character(len=*), intent(in) :: a
        !> Second string.
        character(len=*), intent(in) :: b
        integer :: previous(0:len(b)), current(0:len(b))
        integer :: i, j, cost
        previous = [(j, j=0, len(b))]
        do i = 1, len(a)
            current(0) = i
            do j = 1, len(b)
                cost = merge(0, 1, a(i:i) == b(j:j))
                current(j) = min(previous(j) + 1, current(j - 1) + 1, previous(j - 1) + cost)
            end do
            previous = current
        end do
        distance = previous(len(b))
    end function levenshtein

    !> Candidate closest to `word` by Levenshtein distance, ignoring case; among equally
    !> close candidates, the longest common prefix wins ('mode' gives 'modes' rather than
    !> 'node'), then the first one. `best` is 0 when there is no candidate.
    pure subroutine closest_match(word, candidates, best, distance)
        !> The word to match.
        character(len=*), intent(in) :: word
        !> Valid names.
        type(string_t), intent(in) :: candidates(:)
        !> Index of the closest candidate (0 if `candidates` is empty).
        integer, intent(out) :: best
        !> Its distance (huge(0) if `candidates` is empty).
        integer, intent(out) :: distance
        integer :: i, d, prefix, best_prefix
        best = 0
        distance = huge(0)
        best_prefix = -1
        do i = 1, size(candidates)
            d = levenshtein(to_lower(word), to_lower(candidates(i)%s))
            prefix = common_prefix(to_lower(word), to_lower(candidates(i)%s))
            if (d < distance .or. (d == distance .and. prefix > best_prefix)) then
                best = i
                distance = d
                best_prefix = prefix
            end if
        end do
    end subroutine closest_match

    !> Length of the common prefix of two strings.
    pure integer function common_prefix(a, b) result(n)
        !> First string.
        character(len=*), intent(in) :: a
        !> Second string.
        character(len=*), intent(in) :: b
        n = 0
        do while (n < min(len(a), len(b)))
            if (a(n + 1:n + 1) /= b(n + 1:n + 1)) exit
            n = n + 1
        end do
    end function common_prefix

    !> Parse a real number written as Fortran accepts it in source or input: optional sign,
    !> digits with an optional decimal point, optional exponent `e`/`d` (`7800`, `2E11`,
    !> `1.0e-4`, `-.5`). Anything else (words, `1.2.3`, `1,5`, `nan`, magnitudes of 1e308
    !> and more or below 1e-307 except zero) sets `ok = .false.` and `value = 0`.
    subroutine parse_real(text, value, ok)
        !> The token to parse (no surrounding blanks).
        character(len=*), intent(in) :: text
        !> The value read (0 on failure).
        real(wp), intent(out) :: value
        !> Whether `text` is a valid finite real number.
        logical, intent(out) :: ok
        integer :: ios, magnitude
        value = 0.0_wp
        call scan_real(text, ok, magnitude)
        ! range() is 307 for IEEE double: |x| < 1e308 cannot overflow, |x| >= 1e-307 is normal.
        if (ok) ok = magnitude <= range(value) .and. (magnitude >= -range(value) .or. &
                                                      magnitude == -huge(0))
        if (.not. ok) return
        read (text, *, iostat=ios) value
        ok = ios == 0
        if (ok) ok = ieee_is_finite(value)
        if (.not. ok) value = 0.0_wp
    end subroutine parse_real

    !> Parse an integer: optional sign and decimal digits only (`2.5`, `1e3`, `x` are
    !> rejected, as are values outside the default integer range).
    subroutine parse_int(text, value, ok)
        !> The token to parse (no surrounding blanks).
        character(len=*), intent(in) :: text
        !> The value read (0 on failure).
        integer, intent(out) :: value
        !> Whether `text` is a valid integer in range.
        logical, intent(out) :: ok
        integer :: ios, start
        integer(i8) :: big
        value = 0
        start = 1
        if (len(text) > 0) then
            if (text(1:1) == '+' .or. text(1:1) == '-') start = 2
        end if
        ok = len(text) >= start .and. len(text) - start < 18
        if (ok) ok = verify(text(start:), digits) == 0
        if (.not. ok) return
        read (text, *, iostat=ios) big
        ok = ios == 0
        if (ok) ok = abs(big) <= huge(value)
        if (ok) value = int(big)
    end subroutine parse_int

    !> Whether `text` has the form of a real number (parse_real may still refuse it for its
    !> magnitude).
    pure logical function is_real_syntax(text) result(ok)
        !> The token.
        character(len=*), intent(in) :: text
        integer :: magnitude
        call scan_real(text, ok, magnitude)
    end function is_real_syntax

    !> Check the syntax of a real number (see parse_real) and estimate its decimal magnitude,
    !> so that values beyond the range of real(wp) are rejected before reading them (reading
    !> them would raise a floating-point overflow).
    pure subroutine scan_real(text, ok, magnitude)
        !> The token.
        character(len=*), intent(in) :: text
        !> Whether the syntax is valid.
        logical, intent(out) :: ok
        !> floor(log10(|x|)) (-huge(0) for zero).
        integer, intent(out) :: magnitude
        integer :: i, start, n_int, n_frac, n_exp, lead_int, lead_frac, expo, sgn
        ok = .false.
        magnitude = -huge(0)
        i = 1
        if (i <= len(text)) then
            if (text(i:i) == '+' .or. text(i:i) == '-') i = i + 1
        end if
        start = i
        call count_digits(text, i, n_int)
        lead_int = verify(text(start:i - 1)//'x', '0') - 1
        n_frac = 0
        lead_frac = 0
        if (i <= len(text)) then
            if (text(i:i) == '.') then
                i = i + 1
                start = i
                call count_digits(text, i, n_frac)
                lead_frac = verify(text(start:i - 1)//'x', '0') - 1
            end if
        end if
        if (n_int + n_frac == 0) return
        expo = 0
        if (i <= len(text)) then
            if (scan(text(i:i), 'eEdD') == 0) return
            i = i + 1
            sgn = 1
            if (i <= len(text)) then
                if (text(i:i) == '+' .or. text(i:i) == '-') then
                    if (text(i:i) == '-') sgn = -1
                    i = i + 1
                end if
            end if
            start = i
            call count_digits(text, i, n_exp)
            if (n_exp == 0) return
            ! Exponents beyond 5 digits are out of range anyway: cap them.
            expo = sgn*min(digits_value(text(start:i - 1)), 99999)
        end if
        ok = i > len(text)
        if (n_int > lead_int) then
            magnitude = n_int - lead_int - 1 + expo
        else if (n_frac > lead_frac) then
            magnitude = -lead_frac - 1 + expo
        end if
    end subroutine scan_real

    !> Value of a string of decimal digits, saturating at 10**6.
    pure integer function digits_value(text) result(value)
        !> Decimal digits only.
        character(len=*), intent(in) :: text
        integer :: i
        value = 0
        do i = 1, len(text)
            value = min(10*value + index(digits, text(i:i)) - 1, 1000000)
        end do
    end function digits_value

    !> Count the decimal digits starting at position `i` and move `i` past them.
    pure subroutine count_digits(text, i, n)
        !> The text.
        character(len=*), intent(in) :: text
        !> Position to start at; on return, the first position after the digits.
        integer, intent(inout) :: i
        !> Number of digits found.
        integer, intent(out) :: n
        n = 0
        do while (i <= len(text))
            if (index(digits, text(i:i)) == 0) exit
            n = n + 1
            i = i + 1
        end do
    end subroutine count_digits

    !> Integer as text (`i0`).
    pure function int_to_str(i) result(text)
        !> The integer.
        integer, intent(in) :: i
        character(len=:), allocatable :: text
        character(len=16) :: buf
        write (buf, '(i0)') i
        text = trim(buf)
    end function int_to_str

    !> Count and noun (see `counted`).
    pure function int_counted(n, noun) result(text)
        !> The count.
        integer, intent(in) :: n
        !> The noun, singular; its plural adds an s.
        character(len=*), intent(in) :: noun
        character(len=:), allocatable :: text
        text = int_to_str(n)//' '//noun
        if (n /= 1) text = text//'s'
    end function int_counted

    !> Count and noun, 64-bit count (see `counted`).
    pure function int8_counted(n, noun) result(text)
        !> The count.
        integer(i8), intent(in) :: n
        !> The noun, singular; its plural adds an s.
        character(len=*), intent(in) :: noun
        character(len=:), allocatable :: text
        text = int8_to_str(n)//' '//noun
        if (n /= 1_i8) text = text//'s'
    end function int8_counted

    !> 64-bit integer as text (`i0`).
    pure function int8_to_str(i) result(text)
        !> The integer.
        integer(i8), intent(in) :: i
        character(len=:), allocatable :: text
        character(len=24) :: buf
        write (buf, '(i0)') i
        text = trim(buf)
    end function int8_to_str

    !> A token as echoed in a message: unchanged up to `max_echo` characters, otherwise its
    !> first `max_echo` characters followed by '...' (a pasted line or a binary file then
    !> gives a readable message).
    pure function shorten(text) result(short)
        !> The token as written.
        character(len=*), intent(in) :: text
        character(len=:), allocatable :: short
        if (len(text) <= max_echo) then
            short = text
        else
            short = text(:max_echo)//'...'
        end if
    end function shorten

    !> Real rounded to at most `max_digits` significant digits, as the shortest text that
    !> reads back to the rounded value: plain decimals for magnitudes in [1e-4, 1e7) (`0.25`,
    !> `7800`), otherwise mantissa and exponent (`2.1e11`).
    function real_to_str(x_in) result(text)
        !> The real.
        real(wp), intent(in) :: x_in
        character(len=:), allocatable :: text
        character(len=40) :: buf, fmt
        character(len=:), allocatable :: mantissa
        real(wp) :: back, x
        integer :: d, ios, e_pos, expo, pass
        if (.not. ieee_is_finite(x_in)) then
            write (buf, *) x_in
            text = strip(buf)
            return
        end if
        if (x_in == 0.0_wp) then
            text = '0'
            return
        end if
        ! Fewest significant digits that round-trip; if more than max_digits are needed, the
        ! value rounded to max_digits digits, whose own shortest form is found in pass 2.
        x = x_in
        do pass = 1, 2
            do d = 1, max_digits
                write (fmt, '(a,i0,a,i0,a)') '(es', d + 8, '.', d - 1, 'e3)'
                write (buf, fmt) x
                read (buf, *, iostat=ios) back
                if (ios == 0 .and. back == x) exit
            end do
            if (d <= max_digits) exit
            x = back
        end do
        buf = adjustl(buf)
        e_pos = index(buf, 'E')
        read (buf(e_pos + 1:), *) expo
        mantissa = trim(buf(:e_pos - 1))
        if (expo >= -4 .and. expo < 7) then
            write (fmt, '(a,i0,a)') '(f0.', max(d - 1 - expo, 0), ')'
            write (buf, fmt) x
            text = trim(buf)
            if (text(1:1) == '.') text = '0'//text
            if (text(1:2) == '-.') text = '-0'//text(2:)
            if (text(len(text):len(text)) == '.') text = text(:len(text) - 1)
        else
            if (mantissa(len(mantissa):len(mantissa)) == '.') then
                mantissa = mantissa(:len(mantissa) - 1)
            end if
            text = mantissa//'e'//int_to_str(expo)
        end if
    end function real_to_str

    !> Real in scientific notation with `decimals` digits after the point and a two-digit
    !> exponent, or three digits where the exponent needs them: '5.000E-03', '1.000E+300'.
    !> (A plain `esw.d` edit descriptor drops the letter E of a three-digit exponent and
    !> writes '1.000+300'.)
    function sci_to_str(x, decimals) result(text)
        !> The real.
        real(wp), intent(in) :: x
        !> Digits after the decimal point.
        integer, intent(in) :: decimals
        character(len=:), allocatable :: text
        character(len=60) :: buf, fmt
        integer :: e_pos
        if (.not. ieee_is_finite(x)) then
            text = real_to_str(x)
            return
        end if
        write (fmt, '(a,i0,a,i0,a)') '(es', decimals + 10, '.', decimals, 'e3)'
        write (buf, fmt) x
        text = trim(adjustl(buf))
        e_pos = index(text, 'E')
        if (text(e_pos + 2:e_pos + 2) == '0') text = text(:e_pos + 1)//text(e_pos + 3:)
    end function sci_to_str

    !> A real with 4 significant digits and a three-digit exponent, as messages print
    !> coordinates, times and rates: '4.500E+009', '1.226E-002'.
    function sci_text(x) result(text)
        !> The real.
        real(wp), intent(in) :: x
        character(len=:), allocatable :: text
        character(len=24) :: buf
        write (buf, '(es11.3e3)') x
        text = trim(adjustl(buf))
    end function sci_text

    !> A number of bytes in GiB with two decimals, e.g. '1.50 GiB', '0.25 GiB'.
    function gib(bytes) result(text)
        !> Bytes.
        integer(i8), intent(in) :: bytes
        character(len=:), allocatable :: text
        character(len=32) :: buf
        write (buf, '(f0.2)') real(bytes, wp)/1024.0_wp**3
        text = trim(buf)
        if (text(1:1) == '.') text = '0'//text
        text = text//' GiB'
    end function gib

    !> A path as one word of a POSIX shell command, so that the printed command can be
    !> pasted: as it is when it holds only safe characters, else in single quotes (a quote
    !> inside written '\'').
    pure function shell_word(path) result(word)
        !> The path.
        character(len=*), intent(in) :: path
        character(len=:), allocatable :: word
        character(len=*), parameter :: safe = 'abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789'// &
                                       '_-./+=:,@%'
        integer :: i
        if (len(path) > 0 .and. verify(path, safe) == 0) then
            word = path
            return
        end if
        word = "'"
        do i = 1, len(path)
            if (path(i:i) == "'") then
                word = word//"'\''"
            else
                word = word//path(i:i)
            end if
        end do
        word = word//"'"
    end function shell_word
end module core_strings
