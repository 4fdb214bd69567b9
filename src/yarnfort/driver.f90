! SPDX-License-Identifier: MIT
!> Run a scene: choose the linear solver, set up Newton (KINSOL) and follow the load path;
!> with its outputs, as the program and the Python facade run it.
module yarnfort_driver
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, prefix_error, fatal_error
    use yarnfort_input_config, only: config_type, control_config_type, output_config_type
    use yarnfort_input_echo, only: write_config
    use yarnfort_output_writer, only: output_writer_type
    use yarnfort_output_restart_file, only: read_restart, check_restart, get_input_hash, &
        restart_file_name, synced_file_name
    use yarnfort_text, only: format_integer, string_type, read_line, resolve_path
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_linalg_linear_solver, only: linear_solver_type
    use yarnfort_linalg_factory, only: new_linear_solver, default_linear_solver_name
    use yarnfort_solver_elastic_stepper, only: elastic_stepper_type, new_elastic_stepper
    use yarnfort_solver_continuation, only: step_observer_type, run_continuation
    use yarnfort_contact_friction_stepper, only: friction_stepper_type, new_friction_stepper
    use yarnfort_solver_restart, only: restart_type
    use yarnfort_solver_stepper, only: load_stepper_type
    use yarnfort_solver_force_control, only: force_control_stepper_type, &
        new_force_control_stepper
    implicit none
    private

    public :: run_scene, get_linear_solver_name, solve_with_outputs

contains

    !> The linear solver for the scene's elastic solves: its &solver linear_solver, or
    !> for 'auto' the measured default for its size. With the slack regularisation every
    !> string has positive tension and stiffness, so the elastic tangent is symmetric
    !> positive definite (CHOLMOD, with a KLU fallback should a factorisation say
    !> otherwise); without it, it may be singular or indefinite.
    function get_linear_solver_name(scene) result(name)
        type(scene_type), intent(in) :: scene
        character(len=:), allocatable :: name

        if (trim(scene%solver%linear_solver) == 'auto') then
            name = default_linear_solver_name(int(scene%dofs%n_unknowns, 8), &
                scene%solver%slack_stiffness > 0.0_wp)
        else
            name = trim(scene%solver%linear_solver)
        end if
    end function get_linear_solver_name

    !> Follow the scene's load path; `observer` receives every converged step and its
    !> restart snapshot. With `restart`, go on from that snapshot instead of starting at
    !> the first knot; with `max_steps` > 0, stop after that many converged load steps
    !> (`stopped` then tells whether the path's end was not reached).
    subroutine run_scene(scene, observer, error, restart, max_steps, stopped)
        type(scene_type), target, intent(in) :: scene
        class(step_observer_type), intent(inout) :: observer
        type(error_type), allocatable, intent(out) :: error
        type(restart_type), intent(in), optional :: restart
        integer, intent(in), optional :: max_steps
        logical, intent(out), optional :: stopped
        class(linear_solver_type), allocatable :: linear
        type(elastic_stepper_type), target :: stepper
        type(friction_stepper_type), target :: friction_stepper
        type(force_control_stepper_type), target :: lateral
        type(force_control_stepper_type) :: axial

        if (present(stopped)) stopped = .false.
        ! Only a scene with sliding passages pays for the sliding machinery.
        if (scene%passages%size() > 0) then
            call new_friction_stepper(friction_stepper, scene, get_linear_solver_name(scene), error)
            if (allocated(error)) return
            call run_controlled(friction_stepper)
            return
        end if
        call new_linear_solver(linear, get_linear_solver_name(scene), error)
        if (allocated(error)) then
            call prefix_error(error, '&solver linear_solver')
            return
        end if
        call new_elastic_stepper(stepper, scene, linear, error)
        if (allocated(error)) return
        call run_controlled(stepper)
    contains
        !> Follow the path with `inner`, wrapped for each force-controlled period: an
        !> outer iteration on e22 around every step, and one on e11 around that.
        subroutine run_controlled(inner)
            class(load_stepper_type), target, intent(inout) :: inner

            if (scene%lateral_channel > 0) then
                call new_force_control_stepper(lateral, inner, 2)
                if (scene%axial_channel > 0) then
                    call new_force_control_stepper(axial, lateral, 1)
                    call run_continuation(scene, axial, observer, error, restart, max_steps, &
                        stopped)
                else
                    call run_continuation(scene, lateral, observer, error, restart, max_steps, &
                        stopped)
                end if
            else if (scene%axial_channel > 0) then
                call new_force_control_stepper(axial, inner, 1)
                call run_continuation(scene, axial, observer, error, restart, max_steps, stopped)
            else
                call run_continuation(scene, inner, observer, error, restart, max_steps, stopped)
            end if
        end subroutine run_controlled
    end subroutine run_scene

    !> Solve the built `scene` of `config` with its outputs: render the input's echo and
    !> fingerprint (output/ does not read the input), open the &output folder with
    !> `writer` (with &control restart: lock it, read and check its restart.dat before
    !> touching anything else, tell `writer` (on_resume) and resume after that step),
    !> write the effective input, follow the load path (`stopped`: &control max_steps
    !> reached) and close the files. On failure `stage` says where ('restart', 'output'
    !> or 'solve') and `status` is 2 when nothing of the run was written, 1 after it (the
    !> converged steps are kept). A run error of stat `unwind_stat` is a stop the writer
    !> asked for, not a failure.
    subroutine solve_with_outputs(config, scene, writer, error, stage, status, stopped, &
            unwind_stat)
        type(config_type), intent(in) :: config
        type(scene_type), target, intent(in) :: scene
        class(output_writer_type), intent(inout) :: writer
        type(error_type), allocatable, intent(out) :: error
        character(len=:), allocatable, intent(out) :: stage
        integer, intent(out) :: status
        logical, intent(out) :: stopped
        integer, intent(in), optional :: unwind_stat
        type(restart_type) :: restart
        type(error_type), allocatable :: finish_error
        type(string_type), allocatable :: echo(:), hashed_echo(:)

        stopped = .false.
        status = 2
        stage = 'output'
        call get_echo(config, echo, error)
        if (.not. allocated(error)) call get_echo(get_hashed_config(config), hashed_echo, error)
        if (allocated(error)) return
        writer%input_hash = get_input_hash(hashed_echo, get_named_files(config), scene)
        if (config%control%restart) then
            stage = 'output'
            call writer%lock(config%output%folder, error, create=.false.)
            if (allocated(error)) return
            stage = 'restart'
            call read_restart(trim(config%output%folder), restart, error)
            if (allocated(error)) then
                call add_synced_hint(trim(config%output%folder), -1, error)
                return
            end if
            call check_restart(restart, scene, writer%input_hash, trim(config%output%folder), &
                error)
            if (allocated(error)) return
            call writer%on_resume(restart%step, restart%time)
            stage = 'output'
            call writer%open(scene, error, resume_step=restart%step, resume_time=restart%time, &
                resume_previous_time=restart%time_old)
            if (allocated(error)) call add_synced_hint(trim(config%output%folder), &
                restart%step, error)
        else
            stage = 'output'
            call writer%open(scene, error)
        end if
        if (allocated(error)) return
        call writer%write_input(echo, error)
        if (allocated(error)) then
            call writer%finish(scene, finish_error)     ! releases the folder's lock
            return
        end if

        if (config%control%restart) then
            call run_scene(scene, writer, error, restart=restart, &
                max_steps=config%control%max_steps, stopped=stopped)
        else
            call run_scene(scene, writer, error, max_steps=config%control%max_steps, &
                stopped=stopped)
        end if
        if (allocated(error) .and. present(unwind_stat)) then
            if (error%stat == unwind_stat) deallocate(error)
        end if
        call writer%finish(scene, finish_error)
        status = 1
        if (allocated(error)) then
            if (.not. writer%failed) stage = 'solve'
        else if (allocated(finish_error)) then
            call move_alloc(finish_error, error)
        end if
    end subroutine solve_with_outputs

    !> The lines of `config`'s echo (write_config), rendered through a scratch file.
    subroutine get_echo(config, lines, error)
        type(config_type), intent(in) :: config
        type(string_type), allocatable, intent(out) :: lines(:)
        type(error_type), allocatable, intent(out) :: error
        type(string_type), allocatable :: grown(:)
        character(len=:), allocatable :: line
        character(len=256) :: message
        integer :: unit, status, n

        message = ''
        open(newunit=unit, status='scratch', form='formatted', action='readwrite', &
            iostat=status, iomsg=message)
        if (status /= 0) then
            call fatal_error(error, 'cannot open a scratch file to echo the input: ' &
                // trim(message))
            return
        end if
        call write_config(unit, config)
        rewind(unit)
        allocate(lines(64))
        n = 0
        do
            call read_line(unit, line, status, message)
            if (is_iostat_end(status)) exit
            if (status /= 0) then
                close(unit)
                call fatal_error(error, 'cannot read back the echo of the input: ' &
                    // trim(message))
                return
            end if
            if (n == size(lines)) then
                ! Doubling keeps the copies linear in the echo's length.
                allocate(grown(2 * n))
                grown(:n) = lines
                call move_alloc(grown, lines)
            end if
            n = n + 1
            call move_alloc(line, lines(n)%text)
        end do
        close(unit)
        lines = lines(:n)
    end subroutine get_echo

    !> `config` as the restart fingerprint echoes it: without &control and &output (they
    !> may change between a run and its restart) and without the input folder.
    function get_hashed_config(config) result(copy)
        type(config_type), intent(in) :: config
        type(config_type) :: copy

        copy = config
        copy%control = control_config_type()
        copy%output = output_config_type()
        copy%input_folder = ''
    end function get_hashed_config

    !> The resolved paths of the files `config` names, in the fingerprint's order: the
    !> material tables, the contact rate tables, the geometry file (blank names left out).
    function get_named_files(config) result(files)
        type(config_type), intent(in) :: config
        type(string_type), allocatable :: files(:)
        integer :: m

        allocate(files(0))
        if (allocated(config%materials)) then
            do m = 1, size(config%materials)
                call add(config%materials(m)%table_file)
            end do
        end if
        if (allocated(config%contacts)) then
            do m = 1, size(config%contacts)
                call add(config%contacts(m)%rate_table)
            end do
        end if
        call add(config%geometry%file)
    contains
        subroutine add(name)
            character(len=*), intent(in) :: name
            if (len_trim(name) > 0) &
                files = [files, string_type(resolve_path(name, config%input_folder))]
        end subroutine add
    end function get_named_files

    !> After a power cut, restart.dat may be damaged, or on disk further than curve.csv;
    !> restart.sync, the restart file of the last flush to disk, is then one the tables
    !> hold. Say so in `error` when that file is readable and of an earlier step than
    !> restart.dat's `step` (-1: restart.dat is unreadable).
    subroutine add_synced_hint(folder, step, error)
        character(len=*), intent(in) :: folder
        integer, intent(in) :: step
        type(error_type), intent(inout) :: error
        type(restart_type) :: synced
        type(error_type), allocatable :: unreadable

        call read_restart(folder, synced, unreadable, name=synced_file_name)
        if (allocated(unreadable)) return
        if (step >= 0 .and. synced%step >= step) return
        error%message = error%message // " (after a power cut: '" // folder // '/' &
            // synced_file_name // "' is the restart file last flushed to disk, of step " &
            // format_integer(synced%step) // '; rename it to ' // restart_file_name &
            // ' to go on from there)'
    end subroutine add_synced_hint

end module yarnfort_driver
