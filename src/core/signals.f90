!> Stop requests from the operating system: SIGTERM (Slurm at the time limit, `kill`),
!> SIGINT (Ctrl-C) and SIGUSR1 (`sbatch --signal=USR1@120`, sent before the time limit).
!>
!> `install_signal_handlers` installs a handler (src/core/signals_c.c) that only records the
!> first signal caught; the time loops poll `caught_signal()` once per step, finish the step,
!> write a checkpoint, store the step and close the results (doc/output.md, "Interrupted
!> runs"). After the first
!> delivery a signal has its default action again: a second Ctrl-C or SIGTERM stops the
!> program at once. SIGXFSZ is ignored, so that a file size limit (`ulimit -f`) gives a write
!> error instead of killing the program. The flag lives in the C file (a signal handler can
!> only set a `volatile sig_atomic_t`); this module keeps no state.
module core_signals
    use, intrinsic :: iso_c_binding, only: c_int
    use core_error, only: error_t, make_error
    implicit none
    private
    public :: install_signal_handlers, caught_signal, signal_name, clear_caught_signal, &
              signal_exit_code, stop_signals

    interface
        !> Install the handlers (0 on success).
        integer(c_int) function c_install() bind(c, name='multicor_signals_install')
            import :: c_int
        end function c_install
        !> First signal caught, 0 if none.
        integer(c_int) function c_caught() bind(c, name='multicor_signals_caught')
            import :: c_int
        end function c_caught
        !> Forget the caught signal.
        subroutine c_clear() bind(c, name='multicor_signals_clear')
        end subroutine c_clear
        !> SIGTERM of this platform.
        integer(c_int) function c_sigterm() bind(c, name='multicor_sigterm')
            import :: c_int
        end function c_sigterm
        !> SIGINT of this platform.
        integer(c_int) function c_sigint() bind(c, name='multicor_sigint')
            import :: c_int
        end function c_sigint
        !> SIGUSR1 of this platform.
        integer(c_int) function c_sigusr1() bind(c, name='multicor_sigusr1')
            import :: c_int
        end function c_sigusr1
    end interface

contains

    !> Catch SIGTERM, SIGINT and SIGUSR1 (and ignore SIGXFSZ) from now on.
    subroutine install_signal_handlers(error)
        !> Set when the operating system refuses a handler.
        type(error_t), allocatable, intent(out) :: error
        if (c_install() /= 0) call make_error(error, 'cannot install the signal handlers '// &
                                              '(SIGTERM, SIGINT, SIGUSR1)')
    end subroutine install_signal_handlers

    !> Number of the first stop signal caught since the start (0: none).
    integer function caught_signal()
        caught_signal = int(c_caught())
    end function caught_signal

    !> Forget a caught signal (for tests).
    subroutine clear_caught_signal()
        call c_clear()
    end subroutine clear_caught_signal

    !> Name of a signal number: 'SIGTERM', 'SIGINT', 'SIGUSR1', or 'signal <n>'.
    function signal_name(sig) result(name)
        !> Signal number.
        integer, intent(in) :: sig
        !> Its name.
        character(len=:), allocatable :: name
        character(len=16) :: buf
        if (sig == int(c_sigterm())) then
            name = 'SIGTERM'
        else if (sig == int(c_sigint())) then
            name = 'SIGINT'
        else if (sig == int(c_sigusr1())) then
            name = 'SIGUSR1'
        else
            write (buf, '(a,i0)') 'signal ', sig
            name = trim(buf)
        end if
    end function signal_name

    !> Numbers of the stop signals of this platform: SIGTERM, SIGINT, SIGUSR1.
    function stop_signals() result(sigs)
        !> The three numbers, in that order.
        integer :: sigs(3)
        sigs = [int(c_sigterm()), int(c_sigint()), int(c_sigusr1())]
    end function stop_signals

    !> Exit code of a run stopped by a signal: 128 + the signal number, the shell's
    !> convention (SIGTERM 143, SIGINT 130, SIGUSR1 138 on Linux).
    pure integer function signal_exit_code(sig)
        !> Signal number.
        integer, intent(in) :: sig
        signal_exit_code = 128 + sig
    end function signal_exit_code
end module core_signals
