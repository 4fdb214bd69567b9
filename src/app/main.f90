! SPDX-License-Identifier: MIT
!> yarnfort: stretch a yarn network described by a namelist on standard input.
!>     ./yarnfort < scene.nml
!> Progress goes to stderr; results to the &output folder. Exit code 0 only on success.
program yarnfort_main
    use, intrinsic :: iso_fortran_env, only: error_unit, output_unit, int64, real64
    use yarnfort_error, only: error_type
    use yarnfort_version, only: yarnfort_version_string
    use yarnfort_text, only: format_short
    use yarnfort_input_config, only: config_type
    use yarnfort_input_namelist, only: read_config_from_stdin, check_config
    use yarnfort_input_groups, only: input_help_lines => help_lines
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_generate_fabric, only: generate_fabric
    use yarnfort_scene_builder, only: new_scene
    use yarnfort_driver, only: solve_with_outputs, get_linear_solver_name
    use yarnfort_app_progress, only: progress_writer_type
    use yarnfort_output_filesystem, only: ignore_file_size_signal
    use yarnfort_linalg_process, only: apply_process_settings
    use yarnfort_solver_interrupt, only: catch_interrupts, release_interrupts, interrupt_stat
    implicit none
    type(config_type) :: config
    type(scene_type), target :: scene
    type(progress_writer_type) :: writer
    type(error_type), allocatable :: error
    character(len=:), allocatable :: stage
    integer :: status
    integer(int64) :: clock_start, clock_end, clock_rate
    character(len=16) :: seconds
    logical :: stopped

    call handle_arguments()
    ! A write past a file size limit then fails like any other write (exit 1, message).
    call ignore_file_size_signal()
    ! Threads and heap of the solver libraries, once for the process.
    call apply_process_settings()

    call system_clock(clock_start, clock_rate)
    call read_config_from_stdin(config, error)
    if (allocated(error)) call fail('input', error, 2)
    call generate_fabric(config, error)
    if (allocated(error)) call fail('input', error, 2)
    call check_config(config, error)
    if (allocated(error)) call fail('input', error, 2)
    call new_scene(scene, config, error)
    if (allocated(error)) call fail('input', error, 2)
    call system_clock(clock_end)

    write(error_unit, '(a, i0, a, i0, a, i0, a, a)') 'yarnfort: ', scene%network%n_nodes(), &
        ' nodes, ', scene%network%n_elements(), ' elements, ', scene%dofs%n_unknowns, &
        ' unknowns; linear solver ', get_linear_solver_name(scene)
    if (config%fabric%kind == 'texgen') write(error_unit, '(a, i0, a, i0, a)') &
        'yarnfort: TexGen model: ', config%texgen_yarns, ' yarns, ', config%texgen_contacts, &
        ' contacts (one gap-holder each)'
    write(seconds, '(f16.6)') &
        real(clock_end - clock_start, real64) / real(max(clock_rate, 1_int64), real64)
    write(error_unit, '(a)') 'yarnfort: scene built in ' // trim(adjustl(seconds)) &
        // ' s (input read and checked, fabric generated or imported)'
    if (scene%passages%size() > 0) write(error_unit, '(a, i0, a, a, a)') 'yarnfort: ', &
        scene%passages%size(), ' sliding passages, ', trim(scene%solver%scheme), ' scheme'
    if (config%control%check_only) then
        write(error_unit, '(a)') 'yarnfort: input checked (check_only = .true.), nothing solved'
        stop 0, quiet=.true.
    end if

    writer%progress = config%output%progress
    writer%residual_history = config%output%residual_history
    ! Ctrl-C stops the solve at its next poll (within a Newton iteration); a second one
    ! ends the process at once.
    call catch_interrupts(kill_on_second=.true.)
    call solve_with_outputs(config, scene, writer, error, stage, status, stopped)
    call release_interrupts()
    if (allocated(error)) then
        if (error%stat == interrupt_stat) call stop_interrupted(error)
        call fail(stage, error, status)
    end if
    if (stopped) then
        write(error_unit, '(a, i0, a)') 'yarnfort: stopped after max_steps = ', &
            config%control%max_steps, ' load steps; results so far in ' &
            // trim(config%output%folder) // ' (continue with &control restart = .true.)'
    else
        write(error_unit, '(a)') 'yarnfort: done; results in ' // trim(config%output%folder)
    end if
    if (writer%n_jumps > 0) write(error_unit, '(a, i0, a)') 'yarnfort: note: ', &
        writer%n_jumps, ' step(s) ended in a jump after a slip instability (curve.csv ' &
        // 'column jumped; inputs/REFERENCE.md, Slip instabilities)'
    if (scene%periodic_cell .and. scene%cell_shear /= 0.0_real64) call note_shear()

contains

    !> Say whether the sheared cell showed any shear stiffness in the yarns' frame: a
    !> string net resists shear only by the tension it turns (inputs/REFERENCE.md, Shear).
    subroutine note_shear()
        ! Below this fraction of the membrane forces the frame shear is the solver's
        ! rounding (the built-in cells: 1e-11 at most; the sliding twill 9e-6).
        real(real64), parameter :: zero_shear = 1.0e-8_real64
        character(len=:), allocatable :: ratio

        ratio = format_short(writer%frame_shear / max(writer%membrane_force, tiny(1.0_real64)))
        if (writer%frame_shear <= zero_shear * writer%membrane_force) then
            write(error_unit, '(a)') 'yarnfort: note: no shear stiffness: the shear in the ' &
                // "yarns' frame, n12 cos(gamma12) - n22 sin(gamma12), is zero at every step (" &
                // trim(adjustl(ratio)) // ' of n11, n22): the cell carries tension along ' &
                // 'its periods only, n12 is that tension turned by the shear (a pin-jointed ' &
                // 'net; inputs/REFERENCE.md, Shear)'
        else
            write(error_unit, '(a)') "yarnfort: note: the shear in the yarns' frame, n12 " &
                // 'cos(gamma12) - n22 sin(gamma12), reached ' // trim(adjustl(ratio)) &
                // ' of n11, n22 (sliding at the crossings; inputs/REFERENCE.md, Shear)'
        end if
    end subroutine note_shear

    subroutine handle_arguments()
        integer :: i
        character(len=256) :: argument

        do i = 1, command_argument_count()
            call get_command_argument(i, argument)
            select case (trim(argument))
            case ('--help', '-h')
                call print_help()
                stop 0, quiet=.true.
            case ('--version', '-V')
                write(output_unit, '(a)') 'yarnfort ' // yarnfort_version_string
                stop 0, quiet=.true.
            case default
                write(error_unit, '(a)') "yarnfort: error: unknown argument '" // trim(argument) &
                    // "' (try --help)"
                stop 2, quiet=.true.
            end select
        end do
    end subroutine handle_arguments

    subroutine print_help()
        integer :: i

        write(output_unit, '(a)') &
            'usage: yarnfort [--help | --version] < scene.nml', &
            '', &
            'Simulates the stretching of a network of hyperelastic strings (yarns) described', &
            'by a Fortran namelist read from standard input, following its load path with', &
            "Newton's method (SUNDIALS KINSOL) and sparse direct linear solvers.", &
            '', &
            'A generated knitted or woven fabric (&fabric) replaces &nodes ... &load.', &
            'Load channels: each &load and &support names a channel (&path channels, one', &
            'column of &path factors per channel); default: p_force and p_disp.', &
            'Per-element reference lengths: &yarn length0 or stretch (one per element).', &
            'Table files state their units: a header such as "Elongation (%),Force (cN)"', &
            'or &material strain_unit, force_unit (an elongation in mm: gauge_length);', &
            'none: strain and N. &geometry unit (or a unit line) converts a file to m.', &
            'Examples: inputs/*.nml (installed: python -m yarnfort examples DIR).', &
            ''
        write(output_unit, '(a)') (trim(input_help_lines(i)), i = 1, size(input_help_lines))
        write(output_unit, '(a)') &
            '', &
            'Writes to the &output folder: curve.csv (one row per converged step: channel', &
            'factors, reactions and displacements of the supports, load displacements),', &
            'state_NNNNN.vtu (5 or more digits; binary, or &output vtk_format = ''ascii'')', &
            'with its blocks holders_, links_, passages_NNNNN.vtu, state_NNNNN.vtm (the', &
            'blocks by name) + states.pvd (ParaView: the series of .vtm),', &
            'contacts.csv (one row per sliding passage and step; &output contact_state),', &
            'reactions.csv (with &output node_reactions: one row per constrained node', &
            'and step) and input.nml (the effective input); it lists them in', &
            '.yarnfort-manifest and deletes only files listed there, and holds the lock', &
            '.yarnfort-lock while it runs (a second run into the folder stops at once).', &
            'Progress lines go to stderr. Exit code 0 on success, 1 if the solve or a write', &
            'failed (e.g. a full disk; converged steps are kept), 2 for bad input, an', &
            'unwritable or locked output folder, or a restart file that does not fit, 130', &
            'after Ctrl-C (honoured within a Newton iteration; converged steps are kept).', &
            'After every converged step it also writes restart.dat; &control restart =', &
            '.true. continues a stopped or failed run from its last converged step.'
    end subroutine print_help

    !> After Ctrl-C: what was kept, how to go on, exit code 130 (as after SIGINT).
    subroutine stop_interrupted(error)
        type(error_type), intent(in) :: error
        character(len=:), allocatable :: folder

        folder = trim(config%output%folder)
        write(error_unit, '(a)') 'yarnfort: ' // error%message
        if (index(error%message, 'nothing is kept') > 0) then
            write(error_unit, '(a)') 'yarnfort: run the same input again to start over'
        else
            write(error_unit, '(a)') 'yarnfort: results so far in ' // folder &
                // ' (curve.csv, states, restart.dat); to go on from the last converged ' &
                // 'step, set restart = .true. in the &control group of the same input ' &
                // 'and run it again'
        end if
        stop 130, quiet=.true.
    end subroutine stop_interrupted

    subroutine fail(stage, error, code)
        character(len=*), intent(in) :: stage
        type(error_type), intent(in) :: error
        integer, intent(in) :: code
        write(error_unit, '(a)') 'yarnfort: error (' // stage // '): ' // error%message
        if (code == 1) stop 1, quiet=.true.
        stop 2, quiet=.true.
    end subroutine fail

end program yarnfort_main
