! SPDX-License-Identifier: MIT
!> The rows of reactions.csv (`&output node_reactions`): per converged step, the reaction
!> of every node of every support set, in long format. The file itself is written by a
!> `curve_writer_type` (header, rows appended and flushed per step, resumed on restart).
module yarnfort_output_reactions
    use yarnfort_kinds, only: wp
    use yarnfort_output_csv_rows, only: csv_rows_type
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_solver_continuation, only: step_state_type
    implicit none
    private

    public :: reactions_file_name, reactions_header, get_reaction_rows

    character(len=*), parameter :: reactions_file_name = 'reactions.csv'

    !> Columns: step, support set name, node id, force (N) the support applies on the node.
    character(len=*), parameter :: reactions_header = 'step,support,node,rx,ry,rz'

contains

    !> The rows of one step, joined by newlines (no newline after the last), or '' if the
    !> scene has no constrained node. One row per node of each set, in the order of the
    !> set's coordinates; components the set does not fix are 0.
    function get_reaction_rows(scene, state) result(rows)
        type(scene_type), intent(in) :: scene
        type(step_state_type), intent(in) :: state
        character(len=:), allocatable :: rows
        type(csv_rows_type) :: table
        real(wp) :: force(3)
        integer :: s, i, j, first, node, c
        logical, allocatable :: done(:)

        first = 0
        do s = 1, size(scene%supports)
            associate(coordinates => scene%supports(s)%coordinates)
                allocate(done(size(coordinates)), source=.false.)
                do i = 1, size(coordinates)
                    if (done(i)) cycle
                    node = (coordinates(i) - 1) / 3 + 1
                    force = 0.0_wp
                    do j = i, size(coordinates)
                        c = coordinates(j)
                        if ((c - 1) / 3 + 1 /= node) cycle
                        force(mod(c - 1, 3) + 1) = state%coordinate_reaction(first + j)
                        done(j) = .true.
                    end do
                    call table%new_row()
                    call table%add(state%step)
                    call table%add(trim(scene%supports(s)%name))
                    call table%add(node)
                    call table%add(force)
                end do
                first = first + size(coordinates)
                deallocate(done)
            end associate
        end do
        rows = table%get()
    end function get_reaction_rows

end module yarnfort_output_reactions
