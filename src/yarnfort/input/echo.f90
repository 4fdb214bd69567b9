! SPDX-License-Identifier: MIT
!> The effective input written back as a namelist, for provenance: every variable of
!> every group with its final value, defaults included (each group by the writer
!> generated from its description). `read_config` reads it again to the same
!> `config_type` (reals are written with the shortest text that reads back exactly).
!> With a &geometry file, the nodes and yarns stay in that file.
module yarnfort_input_echo
    use yarnfort_input_config, only: config_type
    use yarnfort_input_groups, only: nodes_config_type, write_control, write_solver, &
        write_material_groups, write_contact_groups, write_fabric, write_nodes, &
        write_geometry, write_yarn_groups, write_support_groups, write_load_groups, &
        write_path, write_output, write_obstacle_groups, write_ring_groups
    use yarnfort_input_fields, only: put
    use yarnfort_text, only: quote_string
    implicit none
    private

    public :: write_config

contains

    !> Write `config` as namelist groups to the formatted sequential unit `unit`.
    subroutine write_config(unit, config)
        integer, intent(in) :: unit
        type(config_type), intent(in) :: config

        call put(unit, '! yarnfort effective input: every namelist variable with its ' &
            // 'value, defaults included')
        call put(unit, '! (a material or contact parameter that is not set is left out).')
        if (len_trim(config%input_folder) > 0) then
            call put(unit, '! Relative file names were resolved against the folder ' &
                // quote_string(config%input_folder) // '.')
        end if
        call write_control(unit, config%control)
        call write_solver(unit, config%solver)
        call write_material_groups(unit, config%materials)
        call write_contact_groups(unit, config%contacts)
        if (len_trim(config%fabric%kind) > 0) then
            ! The fabric generator makes the nodes, yarns and supports.
            call write_fabric(unit, config%fabric)
        else
            call write_geometry(unit, config%geometry)
            if (len_trim(config%geometry%file) > 0) then
                call put(unit, '! The nodes and yarns are those of the geometry file.')
            else
                if (allocated(config%node_positions)) call write_nodes(unit, &
                    nodes_config_type(reshape(config%node_positions, &
                    [size(config%node_positions)])))
                call write_yarn_groups(unit, config%yarns)
            end if
            call write_support_groups(unit, config%supports)
            call write_load_groups(unit, config%loads)
            call write_obstacle_groups(unit, config%obstacles)
            call write_ring_groups(unit, config%rings)
        end if
        if (allocated(config%path%time)) call write_path(unit, config%path)
        call write_output(unit, config%output)
    end subroutine write_config

end module yarnfort_input_echo
