! SPDX-License-Identifier: MIT
!> Run a scene from a namelist file for the Python facade, as the program does with the
!> same file on standard input: the same files (curve.csv, VTK states, input.nml,
!> restart.dat), `&control restart` and `max_steps` honoured, relative file names taken
!> from the working directory. Instead of progress lines, a call-back after every
!> converged step, which can ask the run to stop there. Kept out of `yarnfort_facade`,
!> which f2py reads, because f2py cannot parse derived types with type-bound procedures.
module yarnfort_facade_scene_runner
    use, intrinsic :: iso_c_binding, only: c_double, c_int
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error, prefix_error
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_solver_continuation, only: step_state_type
    use yarnfort_solver_restart, only: restart_type
    use yarnfort_input_config, only: config_type
    use yarnfort_input_namelist, only: read_config_from_file, check_config
    use yarnfort_generate_fabric, only: generate_fabric
    use yarnfort_scene_builder, only: new_scene
    use yarnfort_output_writer, only: output_writer_type
    use yarnfort_driver, only: solve_with_outputs
    use yarnfort_solver_interrupt, only: catch_interrupts, release_interrupts, interrupt_stat
    implicit none
    private

    public :: run_scene_from_file, step_callback_interface
    public :: status_input, status_solve, outcome_done, outcome_max_steps, outcome_stopped, &
        outcome_interrupted

    !> Error status for bad input or an unusable output folder (the program's exit code).
    integer, parameter :: status_input = 2
    !> Error status for a failed solve, or an output error after it (the program's exit
    !> code); the converged steps are kept.
    integer, parameter :: status_solve = 1

    !> How a run without error ended: the path's end reached, `&control max_steps`
    !> reached, stopped on the call-back's request (at a step boundary), or by Ctrl-C
    !> (the step being solved abandoned; the error, of stat interrupt_stat, says what
    !> was kept).
    integer, parameter :: outcome_done = 0, outcome_max_steps = 1, outcome_stopped = 2, &
        outcome_interrupted = 3

    !> Marker status of the error that unwinds the continuation after a stop request.
    integer, parameter :: status_stop_request = -1

    abstract interface
        !> Called after every converged step (step 0 included) once its files are written;
        !> returns 0 to go on, anything else to stop the run after this step.
        function step_callback_interface(step, time, time_start, time_end, p_force, &
                p_disp, iterations, residual, n_slipping, n_passages, wall_time) result(answer)
            import :: c_double, c_int
            integer(c_int), intent(in) :: step, iterations, n_slipping, n_passages
            real(c_double), intent(in) :: time, time_start, time_end, p_force, p_disp, &
                residual, wall_time
            integer(c_int) :: answer
        end function step_callback_interface
    end interface

    !> The library's file writer, silent, counting the converged steps it wrote and
    !> reporting each to the call-back.
    type, extends(output_writer_type) :: facade_writer_type
        !> Converged steps written by this run (step 0, the initial equilibrium, included).
        integer :: n_steps = 0
        !> Start and end of the load path's pseudo-time.
        real(wp) :: time_start = 0.0_wp, time_end = 0.0_wp
        !> The call-back asked to stop after the step just written.
        logical :: stop_requested = .false.
        procedure(step_callback_interface), pointer, nopass :: notify => null()
    contains
        procedure :: on_step
        procedure :: on_checkpoint
    end type facade_writer_type

contains

    !> Read, check and build the scene in the namelist file `path`, then solve its load
    !> path writing the outputs to its &output folder (returned in `folder`), as
    !> `yarnfort < path` does: relative file names in the input and a relative &output
    !> folder are taken from the working directory, `&control restart` continues from the
    !> folder's restart.dat and `max_steps` stops the run early. `notify` is called after
    !> every converged step. `n_steps`: converged steps written by this run (rows added to
    !> curve.csv). `outcome`: outcome_done, outcome_max_steps or outcome_stopped. With
    !> &control check_only nothing is solved or written. On failure `error%stat` is
    !> `status_input` or `status_solve` and the message starts with the stage (input,
    !> restart, output, solve). With `catch`, SIGINT (Ctrl-C) during the solve stops it
    !> within a Newton iteration: outcome_interrupted, and `error` (stat interrupt_stat)
    !> says what was kept.
    subroutine run_scene_from_file(path, notify, catch, n_steps, folder, outcome, error)
        character(len=*), intent(in) :: path
        procedure(step_callback_interface) :: notify
        logical, intent(in) :: catch
        integer, intent(out) :: n_steps, outcome
        character(len=:), allocatable, intent(out) :: folder
        type(error_type), allocatable, intent(out) :: error
        type(config_type) :: config
        type(scene_type), target :: scene
        type(facade_writer_type) :: writer
        character(len=:), allocatable :: stage
        integer :: status
        logical :: stopped

        n_steps = 0
        outcome = outcome_done
        folder = ''
        call read_config_from_file(path, config, error, from_working_directory=.true.)
        if (.not. allocated(error)) call generate_fabric(config, error)
        if (.not. allocated(error)) then
            folder = trim(config%output%folder)
            call check_config(config, error)
        end if
        if (.not. allocated(error)) call new_scene(scene, config, error)
        if (allocated(error)) then
            call set_stage(error, 'input', status_input)
            return
        end if
        if (config%control%check_only) return

        writer%notify => notify
        writer%time_start = scene%path%time(1)
        writer%time_end = scene%path%time(size(scene%path%time))
        if (catch) call catch_interrupts(kill_on_second=.false.)
        call solve_with_outputs(config, scene, writer, error, stage, status, stopped, &
            unwind_stat=status_stop_request)
        if (catch) call release_interrupts()
        n_steps = writer%n_steps
        if (allocated(error)) then
            if (error%stat == interrupt_stat) then
                outcome = outcome_interrupted
                return
            end if
        end if
        if (stopped) outcome = outcome_max_steps
        if (writer%stop_requested .and. .not. allocated(error)) outcome = outcome_stopped
        if (allocated(error)) call set_stage(error, stage, status)
    end subroutine run_scene_from_file

    !> Write the step with the parent writer, count it, and report it to the call-back.
    subroutine on_step(self, scene, state, error)
        class(facade_writer_type), intent(inout) :: self
        type(scene_type), intent(in) :: scene
        type(step_state_type), intent(in) :: state
        type(error_type), allocatable, intent(out) :: error

        call self%output_writer_type%on_step(scene, state, error)
        if (allocated(error)) return
        self%n_steps = self%n_steps + 1
        if (.not. associated(self%notify)) return
        self%stop_requested = self%notify(int(state%step, c_int), &
            real(state%time, c_double), real(self%time_start, c_double), &
            real(self%time_end, c_double), &
            real(channel_factor(1), c_double), real(channel_factor(2), c_double), &
            int(state%newton_iterations, c_int), real(state%newton%residual_norm, c_double), &
            int(state%n_slipping, c_int), int(state%n_passages, c_int), &
            real(state%wall_time, c_double)) /= 0_c_int
    contains
        !> The factor of load channel c (p_force, p_disp without &path channels); 0 if the
        !> path has fewer channels.
        real(wp) function channel_factor(c)
            integer, intent(in) :: c
            channel_factor = 0.0_wp
            if (c <= size(state%factors)) channel_factor = state%factors(c)
        end function channel_factor
    end subroutine on_step

    !> Write the restart file of the step just written; then, if the call-back asked
    !> for it, stop the continuation with a marker error (the step is complete on disk).
    subroutine on_checkpoint(self, scene, snapshot, error)
        class(facade_writer_type), intent(inout) :: self
        type(scene_type), intent(in) :: scene
        type(restart_type), intent(in) :: snapshot
        type(error_type), allocatable, intent(out) :: error

        call self%output_writer_type%on_checkpoint(scene, snapshot, error)
        if (allocated(error) .or. .not. self%stop_requested) return
        call fatal_error(error, 'stopped on request')
        error%stat = status_stop_request
    end subroutine on_checkpoint

    !> Name the stage in front of the message and set the status.
    subroutine set_stage(error, stage, status)
        type(error_type), intent(inout) :: error
        character(len=*), intent(in) :: stage
        integer, intent(in) :: status

        call prefix_error(error, stage)
        error%stat = status
    end subroutine set_stage

end module yarnfort_facade_scene_runner
