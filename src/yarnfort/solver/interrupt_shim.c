/* SPDX-License-Identifier: MIT */
/* The process-wide interrupt flag (yarnfort_solver_interrupt): a SIGINT handler that only
 * sets it (async-signal-safe), and the calls that install, poll and remove it. The solver
 * polls the flag in its loops and stops at the next residual evaluation, so Ctrl-C is
 * honoured within one Newton iteration without unwinding through C libraries. */
#include <signal.h>
#include <string.h>

static volatile sig_atomic_t interrupt_flag = 0;
static volatile sig_atomic_t second_kills = 0;
static struct sigaction previous_action;
static int installed = 0;

static void on_interrupt(int number)
{
    /* A second Ctrl-C while the first is being honoured (a factorisation that takes
     * long) ends the process as SIGINT would without the handler. */
    if (interrupt_flag && second_kills) {
        signal(number, SIG_DFL);
        raise(number);
        return;
    }
    interrupt_flag = 1;
}

/* Catch SIGINT into the flag (cleared); the handler it replaces is kept for
 * yarnfort_release_interrupts. `kill_on_second`: a second SIGINT ends the process. */
void yarnfort_catch_interrupts(int kill_on_second)
{
    struct sigaction action;

    memset(&action, 0, sizeof action);
    action.sa_handler = on_interrupt;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESTART;
    interrupt_flag = 0;
    second_kills = kill_on_second != 0;
    if (installed) return;
    if (sigaction(SIGINT, &action, &previous_action) == 0) installed = 1;
}

/* Put back the SIGINT handler yarnfort_catch_interrupts replaced. */
void yarnfort_release_interrupts(void)
{
    if (!installed) return;
    sigaction(SIGINT, &previous_action, NULL);
    installed = 0;
}

/* 1 once SIGINT arrived since yarnfort_catch_interrupts (or was requested), else 0. */
int yarnfort_interrupt_requested(void)
{
    return interrupt_flag != 0;
}

/* Set the flag as SIGINT would (tests, and callers with their own signal handling). */
void yarnfort_request_interrupt(void)
{
    interrupt_flag = 1;
}

/* Clear the flag. */
void yarnfort_clear_interrupt(void)
{
    interrupt_flag = 0;
}
