! SPDX-License-Identifier: MIT
!> The rows of contacts.csv (`&output contact_state`): per converged step, the state of
!> every sliding passage (a yarn through a contact node) in long format, written by
!> `contacts_writer_type` (a table_writer_type: rows appended and flushed per step,
!> resumed on restart).
module yarnfort_output_contacts
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type
    use yarnfort_output_table, only: table_writer_type
    use yarnfort_output_csv_rows, only: csv_rows_type
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_solver_continuation, only: step_state_type
    use yarnfort_contact_wrap_angle, only: get_wrap_angle
    use yarnfort_contact_friction_problem, only: mode_forward, mode_backward
    use yarnfort_contact_passages, only: is_at_minimum_length
    implicit none
    private

    public :: contacts_writer_type, contacts_file_name, contacts_header, get_contact_rows
    public :: passage_state_type, get_passage_states, mode_names
    public :: mode_none, mode_code_stick, mode_code_forward, mode_code_backward, mode_code_locked

    !> Codes of a passage's mode (the VTK point data `mode`; 0: no passage at the node).
    integer, parameter :: mode_none = 0, mode_code_stick = 1, mode_code_forward = 2, &
        mode_code_backward = 3, mode_code_locked = 4
    !> The mode words of contacts.csv, by code 1..4.
    character(len=8), parameter :: mode_names(4) = [character(len=8) :: 'stick', 'forward', &
        'backward', 'locked']

    !> The state of every sliding passage at a converged step (contacts.csv, VTK).
    type :: passage_state_type
        !> Flow (m), smaller and larger tension (N, clipped at 0), T_crit(T_min, alpha)
        !> (N) and wrap angle alpha (rad), per passage.
        real(wp), allocatable :: flow(:), tension_min(:), tension_max(:), critical(:), angle(:)
        !> Mode code per passage (mode_code_*).
        integer, allocatable :: mode(:)
    end type passage_state_type

    character(len=*), parameter :: contacts_file_name = 'contacts.csv'

    !> Columns: step, passage, contact node, yarn, flow (m of reference length moved from
    !> the element before the node to the one after it since the start), mode, the
    !> smaller and larger of the two tensions (N, clipped at 0), T_crit(T_min, alpha) (N)
    !> and the wrap angle alpha (rad).
    character(len=*), parameter :: contacts_header = 'step,passage,node,yarn,flow,mode,' &
        // 'tension_min,tension_max,critical_tension,wrap_angle'

    !> Only the wrap angle's derivative uses its floor of sin(gamma): any value will do.
    real(wp), parameter :: unused_min_sine = 1.0e-8_wp

    type, extends(table_writer_type) :: contacts_writer_type
    contains
        procedure :: open => open_contacts
        !> Keep the rows up to a step of an existing contacts.csv and append after them.
        procedure :: resume => resume_contacts
        procedure :: write_step
    end type contacts_writer_type

contains

    !> Create folder/contacts.csv and write its header.
    subroutine open_contacts(self, folder, error)
        class(contacts_writer_type), intent(inout) :: self
        character(len=*), intent(in) :: folder
        type(error_type), allocatable, intent(out) :: error

        call self%open_table(folder, contacts_file_name, contacts_header, error)
    end subroutine open_contacts

    !> Continue folder/contacts.csv after `step` (a restart).
    subroutine resume_contacts(self, folder, step, error)
        class(contacts_writer_type), intent(inout) :: self
        character(len=*), intent(in) :: folder
        integer, intent(in) :: step
        type(error_type), allocatable, intent(out) :: error

        call self%resume_table(folder, contacts_file_name, contacts_header, step, error)
    end subroutine resume_contacts

    !> Append the rows of `state` with the snapshot's passage `mode` and `flow`.
    subroutine write_step(self, scene, state, mode, flow, error)
        class(contacts_writer_type), intent(inout) :: self
        type(scene_type), intent(in) :: scene
        type(step_state_type), intent(in) :: state
        integer, intent(in) :: mode(:)
        real(wp), intent(in) :: flow(:)
        type(error_type), allocatable, intent(out) :: error

        call self%put_line(get_contact_rows(scene, state, mode, flow), error)
    end subroutine write_step

    !> The state of every passage at `state`; `mode` and `flow` are the snapshot's. Mode:
    !> 'forward' / 'backward' while the yarn slides towards the element after / before
    !> the node; 'locked' for a stick passage whose element on its low-tension side is at
    !> its minimum length (`&solver min_length_ratio`): it would slide but has no material
    !> left to give; 'stick' otherwise.
    subroutine get_passage_states(scene, state, mode, flow, passages_state)
        type(scene_type), intent(in) :: scene
        type(step_state_type), intent(in) :: state
        integer, intent(in) :: mode(:)
        real(wp), intent(in) :: flow(:)
        type(passage_state_type), intent(out) :: passages_state
        real(wp) :: t_before, t_after, angle, critical, d1, d2, dangle(3, 3)
        integer :: p, before, after, n

        n = scene%passages%size()
        allocate(passages_state%flow(n), passages_state%tension_min(n), &
            passages_state%tension_max(n), passages_state%critical(n), &
            passages_state%angle(n), passages_state%mode(n))
        associate(passages => scene%passages, net => scene%network)
            do p = 1, n
                before = passages%element_before(p)
                after = passages%element_after(p)
                t_before = max(state%tension(before), 0.0_wp)
                t_after = max(state%tension(after), 0.0_wp)
                call get_wrap_angle(state%position(:, net%element_nodes(1, before)), &
                    state%position(:, passages%node(p)), &
                    state%position(:, net%element_nodes(2, after)), unused_min_sine, &
                    angle, dangle)
                associate(law => scene%friction(passages%law(p))%law)
                    call law%get_critical_tension(min(t_before, t_after), angle, critical, &
                        d1, d2)
                end associate
                if (mode(p) == mode_forward) then
                    passages_state%mode(p) = mode_code_forward
                else if (mode(p) == mode_backward) then
                    passages_state%mode(p) = mode_code_backward
                else if ((t_after >= t_before .and. at_minimum(before)) &
                        .or. (t_before >= t_after .and. at_minimum(after))) then
                    passages_state%mode(p) = mode_code_locked
                else
                    passages_state%mode(p) = mode_code_stick
                end if
                passages_state%flow(p) = flow(p)
                passages_state%tension_min(p) = min(t_before, t_after)
                passages_state%tension_max(p) = max(t_before, t_after)
                passages_state%critical(p) = critical
                passages_state%angle(p) = angle
            end do
        end associate
    contains
        !> Whether element e's reference length is at its minimum (as the friction
        !> stepper judges it).
        logical function at_minimum(e)
            integer, intent(in) :: e
            at_minimum = is_at_minimum_length(state%length0(e), scene%network%length0(e), &
                scene%passages%share(e), scene%solver%min_length_ratio, &
                scene%solver%residual_tolerance * scene%length_scale)
        end function at_minimum
    end subroutine get_passage_states

    !> The rows of one step, joined by newlines (no newline after the last); modes as
    !> get_passage_states gives them.
    function get_contact_rows(scene, state, mode, flow) result(rows)
        type(scene_type), intent(in) :: scene
        type(step_state_type), intent(in) :: state
        integer, intent(in) :: mode(:)
        real(wp), intent(in) :: flow(:)
        character(len=:), allocatable :: rows
        type(passage_state_type) :: passages_state
        type(csv_rows_type) :: table
        integer :: p

        call get_passage_states(scene, state, mode, flow, passages_state)
        associate(passages => scene%passages, ps => passages_state)
            do p = 1, passages%size()
                call table%new_row()
                call table%add(state%step)
                call table%add(p)
                call table%add(passages%node(p))
                call table%add(passages%yarn(p))
                call table%add(ps%flow(p))
                call table%add(trim(mode_names(ps%mode(p))))
                call table%add(ps%tension_min(p))
                call table%add(ps%tension_max(p))
                call table%add(ps%critical(p))
                call table%add(ps%angle(p))
            end do
        end associate
        rows = table%get()
    end function get_contact_rows

end module yarnfort_output_contacts
