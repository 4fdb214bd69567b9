! SPDX-License-Identifier: MIT
!> The process-wide interrupt flag: Ctrl-C (SIGINT) sets it, the solver's loops poll it
!> (every residual evaluation, every active-set round, every load step) and stop with an
!> error of stat `interrupt_stat`; the converged steps are kept. The program and the
!> Python entry point install the handler around a run (process-wide, made explicitly).
module yarnfort_solver_interrupt
    use, intrinsic :: iso_c_binding, only: c_int
    use yarnfort_error, only: error_type, fatal_error
    implicit none
    private

    public :: catch_interrupts, release_interrupts, interrupt_requested, request_interrupt, &
        clear_interrupt, check_interrupt, interrupt_stat

    !> Stat of the error an interrupt raises (the shell's exit code after SIGINT, 128 + 2).
    integer, parameter :: interrupt_stat = 130

    interface
        subroutine catch_interrupts_c(kill_on_second) bind(C, name='yarnfort_catch_interrupts')
            import :: c_int
            integer(c_int), value :: kill_on_second
        end subroutine catch_interrupts_c
        !> Put back the SIGINT handler catch_interrupts replaced.
        subroutine release_interrupts() bind(C, name='yarnfort_release_interrupts')
        end subroutine release_interrupts
        integer(c_int) function interrupt_requested_c() &
                bind(C, name='yarnfort_interrupt_requested')
            import :: c_int
        end function interrupt_requested_c
        !> Set the flag as SIGINT would.
        subroutine request_interrupt() bind(C, name='yarnfort_request_interrupt')
        end subroutine request_interrupt
        !> Clear the flag.
        subroutine clear_interrupt() bind(C, name='yarnfort_clear_interrupt')
        end subroutine clear_interrupt
    end interface

contains

    !> Catch SIGINT into the flag, cleared now; with `kill_on_second` a second SIGINT ends
    !> the process at once (for a solve stuck where the flag is not polled).
    subroutine catch_interrupts(kill_on_second)
        logical, intent(in) :: kill_on_second

        call catch_interrupts_c(merge(1_c_int, 0_c_int, kill_on_second))
    end subroutine catch_interrupts

    !> Whether SIGINT arrived (or was requested) since the flag was last cleared.
    logical function interrupt_requested()
        interrupt_requested = interrupt_requested_c() /= 0_c_int
    end function interrupt_requested

    !> An error of stat interrupt_stat in `error` when the flag is set, else none.
    subroutine check_interrupt(error)
        type(error_type), allocatable, intent(out) :: error

        if (interrupt_requested()) call fatal_error(error, 'interrupted (SIGINT, Ctrl-C)', &
            stat=interrupt_stat)
    end subroutine check_interrupt

end module yarnfort_solver_interrupt
