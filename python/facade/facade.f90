! SPDX-License-Identifier: MIT
!> Flat facade of the library for the f2py extension module `yarnfort._yarnfort`
!> (python/meson.build runs numpy.f2py on this file only; the work is done in
!> yarnfort_facade_laws and yarnfort_facade_scene_runner).
!>
!> Only scalars, explicit-shape arrays and character strings cross the boundary, in C
!> kinds converted to the library's kinds here; no derived types. Every routine returns
!> an integer `status`, 0 on success, and a `message`, blank on success, else the
!> library's error message (cut to `text_length` characters). Nothing here prints or stops.
!>
!> f2py resolves only parameters declared in the wrapped routine itself, so each routine
!> declares its own `text_length`. `run_scene_file` takes a Python call-back, which f2py
!> supports only for routines outside a module: it follows the module.
module yarnfort_facade
    use, intrinsic :: iso_c_binding, only: c_double, c_int
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type
    use yarnfort_facade_laws, only: get_force_law_values, get_critical_tensions
    use yarnfort_linalg_process, only: apply_library_settings => apply_process_settings
    implicit none
    private

    public :: force_law_eval, friction_critical_tension, process_settings
    ! For run_scene_file (outside the module); not wrapped by f2py.
    public :: set_status, cut_text

    !> Status of a law or parameter the library refuses (the program's exit code for
    !> bad input).
    integer(c_int), parameter :: status_bad_law = 2_c_int

    !> Marker that ends a message cut to fit its string.
    character(len=*), parameter :: cut_marker = ' [...]'

contains

    !> Make the process-wide settings of the solver libraries (threads, heap) as the
    !> program does at its start; yarnfort._native calls it once, when it loads the
    !> extension. Only the first call does anything.
    subroutine process_settings()
        call apply_library_settings()
    end subroutine process_settings

    !> Tension, its derivative with respect to stretch and the energy per unit reference
    !> length of a force law at each stretch. `law`: 'linear' (p1 = EA in N),
    !> 'neo_hookean' (p1 = modulus C in Pa, p2 = area S1 in m**2) or 'table'
    !> (`table_file`: CSV of strain, force in N). Unused parameters are ignored.
    subroutine force_law_eval(law, p1, p2, table_file, stretch, n, force, dforce, energy, &
            status, message)
        !> Length of `message`.
        integer, parameter :: text_length = 1024
        character(len=*), intent(in) :: law
        real(c_double), intent(in) :: p1, p2
        character(len=*), intent(in) :: table_file
        integer(c_int), intent(in) :: n
        real(c_double), intent(in) :: stretch(n)
        real(c_double), intent(out) :: force(n), dforce(n), energy(n)
        integer(c_int), intent(out) :: status
        character(len=text_length), intent(out) :: message
        type(error_type), allocatable :: error
        real(wp), allocatable :: force_wp(:), dforce_wp(:), energy_wp(:)

        call get_force_law_values(law, real(p1, wp), real(p2, wp), table_file, &
            real(stretch, wp), force_wp, dforce_wp, energy_wp, error)
        force = real(force_wp, c_double)
        dforce = real(dforce_wp, c_double)
        energy = real(energy_wp, c_double)
        call set_status(error, status, message)
        ! A law the library refuses is bad input, like a bad &material in a scene.
        if (status /= 0_c_int) status = status_bad_law
    end subroutine force_law_eval

    !> Critical tension T_crit(T_min, alpha) of a friction law and its derivatives with
    !> respect to T_min and alpha at each pair (tension_min(i), angle(i)). `law`:
    !> 'coulomb' (mu), 'adhesion' (mu, beta), 'decaying_adhesion' (mu, beta, w_d, s_d) or
    !> 'general' (`rate_table`: CSV of T, g). Unused parameters are ignored.
    subroutine friction_critical_tension(law, mu, beta, w_d, s_d, rate_table, tension_min, &
            angle, n, critical, dcrit_dtension, dcrit_dangle, status, message)
        !> Length of `message`.
        integer, parameter :: text_length = 1024
        character(len=*), intent(in) :: law, rate_table
        real(c_double), intent(in) :: mu, beta, w_d, s_d
        integer(c_int), intent(in) :: n
        real(c_double), intent(in) :: tension_min(n), angle(n)
        real(c_double), intent(out) :: critical(n), dcrit_dtension(n), dcrit_dangle(n)
        integer(c_int), intent(out) :: status
        character(len=text_length), intent(out) :: message
        type(error_type), allocatable :: error
        real(wp), allocatable :: critical_wp(:), dtension_wp(:), dangle_wp(:)

        call get_critical_tensions(law, real(mu, wp), real(beta, wp), real(w_d, wp), &
            real(s_d, wp), rate_table, real(tension_min, wp), real(angle, wp), critical_wp, &
            dtension_wp, dangle_wp, error)
        critical = real(critical_wp, c_double)
        dcrit_dtension = real(dtension_wp, c_double)
        dcrit_dangle = real(dangle_wp, c_double)
        call set_status(error, status, message)
        if (status /= 0_c_int) status = status_bad_law
    end subroutine friction_critical_tension

    !> Status 0 and a blank message without an error, else the error's status (at least 1)
    !> and message.
    subroutine set_status(error, status, message)
        type(error_type), allocatable, intent(in) :: error
        integer(c_int), intent(out) :: status
        character(len=*), intent(out) :: message

        if (.not. allocated(error)) then
            status = 0_c_int
            message = ''
            return
        end if
        status = int(max(error%stat, 1), c_int)
        if (allocated(error%message)) then
            call cut_text(error%message, message)
        else
            message = 'unknown error'
        end if
    end subroutine set_status

    !> Copy `text` to `buffer`, ending with `cut_marker` when it does not fit.
    subroutine cut_text(text, buffer)
        character(len=*), intent(in) :: text
        character(len=*), intent(out) :: buffer

        if (len(text) <= len(buffer)) then
            buffer = text
        else
            buffer = text(:len(buffer) - len(cut_marker)) // cut_marker
        end if
    end subroutine cut_text

end module yarnfort_facade

!> Run the scene in the namelist file `path` as `yarnfort < path` does (relative names from
!> the working directory, `&control restart` and `max_steps` honoured), writing curve.csv,
!> the VTK states, input.nml and restart.dat to its &output `folder`, without progress
!> lines. `notify(step, time, time_start, time_end, p_force, p_disp, iterations, residual,
!> n_slipping, n_passages, wall_time)` is called after every converged step once its files are
!> written; a non-zero answer stops the run there (as `max_steps` would). It is called a
!> last time with step = -1 when the run ends, whatever the outcome. With
!> `catch_interrupts` /= 0, SIGINT (Ctrl-C) during the solve stops it within a Newton
!> iteration (the handler it replaces is put back after the run).
!> `n_steps`: converged steps written by this run (rows added to curve.csv; also set after
!> a failed solve, whose steps are kept). `outcome`: 0 the path's end was reached, 1
!> stopped by `max_steps`, 2 stopped by the call-back, 3 interrupted (status 0, and
!> `message` says which steps were kept). Status: 2 for bad input, a bad restart file
!> or an unusable output folder, 1 for a failed solve.
subroutine run_scene_file(path, notify, catch_interrupts, status, message, n_steps, folder, &
        outcome)
    use, intrinsic :: iso_c_binding, only: c_double, c_int
    use yarnfort_error, only: error_type
    use yarnfort_facade, only: set_status, cut_text
    use yarnfort_facade_scene_runner, only: run_scene_from_file, outcome_interrupted
    implicit none
    !> Length of `message` and `folder` (above the input's path length, 512).
    integer, parameter :: text_length = 1024
    character(len=*), intent(in) :: path
    integer(c_int), external :: notify
    integer(c_int), intent(in) :: catch_interrupts
    integer(c_int), intent(out) :: status
    character(len=text_length), intent(out) :: message
    integer(c_int), intent(out) :: n_steps
    character(len=text_length), intent(out) :: folder
    integer(c_int), intent(out) :: outcome
    type(error_type), allocatable :: error
    character(len=:), allocatable :: folder_text
    integer(c_int) :: step, iterations, n_slipping, n_passages, answer
    real(c_double) :: time, time_start, time_end, p_force, p_disp, residual, wall_time
    integer :: steps, how

    call run_scene_from_file(trim(path), notify, catch_interrupts /= 0_c_int, steps, &
        folder_text, how, error)
    n_steps = int(steps, c_int)
    outcome = int(how, c_int)
    call cut_text(folder_text, folder)
    call set_status(error, status, message)
    if (how == outcome_interrupted) status = 0_c_int
    ! The closing call (step -1): the same signature, so that f2py sees it here.
    step = -1_c_int
    iterations = 0_c_int
    n_slipping = 0_c_int
    n_passages = 0_c_int
    time = 0.0_c_double
    time_start = 0.0_c_double
    time_end = 0.0_c_double
    p_force = 0.0_c_double
    p_disp = 0.0_c_double
    residual = 0.0_c_double
    wall_time = 0.0_c_double
    answer = notify(step, time, time_start, time_end, p_force, p_disp, iterations, &
        residual, n_slipping, n_passages, wall_time)
end subroutine run_scene_file
