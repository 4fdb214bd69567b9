! SPDX-License-Identifier: MIT
!> The effective input written back as a namelist, for provenance: every variable of
!> every group with its final value, defaults included. `read_config` reads it again to
!> the same `config_type` (reals are written with the shortest text that reads back
!> exactly). With a &geometry file, the nodes and yarns stay in that file.
module yarnfort_input_echo
    use yarnfort_kinds, only: wp
    use yarnfort_input_config, only: config_type
    use yarnfort_input_text, only: format_integer, format_real, quote_string
    implicit none
    private

    public :: write_config

    !> Values per line of integer lists and of real lists (&path).
    integer, parameter :: integers_per_line = 10
    integer, parameter :: reals_per_line = 4
    character(len=*), parameter :: indent = '    '

contains

    !> Write `config` as namelist groups to the formatted sequential unit `unit`. With
    !> `status`, a failed write stops the writing and its iostat (and iomsg in
    !> `message`) is returned instead of ending the program.
    subroutine write_config(unit, config, status, message)
        integer, intent(in) :: unit
        type(config_type), intent(in) :: config
        integer, intent(out), optional :: status
        character(len=*), intent(inout), optional :: message
        integer :: k, n, stat
        character(len=256) :: iomsg
        logical :: from_file

        stat = 0
        iomsg = ''

        call put('! yarnfort effective input: every namelist variable with its value, ' &
            // 'defaults included')
        call put('! (-1 marks a material or contact parameter that is not set).')
        if (len_trim(config%input_folder) > 0) then
            call put('! Relative file names were resolved against the folder ' &
                // quote_string(config%input_folder) // '.')
        end if

        call put('&control')
        call put(indent // 'title = ' // quote_string(config%control%title))
        call put(indent // 'check_only = ' // format_logical(config%control%check_only))
        call put(indent // 'restart = ' // format_logical(config%control%restart))
        call put(indent // 'max_steps = ' // format_integer(config%control%max_steps))
        call put('/')

        associate(solver => config%solver)
            call put('&solver')
            ! The preset and every value it gave: the explicit values read back the same.
            call put(indent // 'preset = ' // quote_string(solver%preset))
            call put(indent // 'linear_solver = ' // quote_string(solver%linear_solver))
            call put(indent // 'residual_tolerance = ' // format_real(solver%residual_tolerance))
            call put(indent // 'step_tolerance = ' // format_real(solver%step_tolerance))
            call put(indent // 'max_iterations = ' // format_integer(solver%max_iterations))
            call put(indent // 'max_setup_calls = ' // format_integer(solver%max_setup_calls))
            call put(indent // 'line_search = ' // format_logical(solver%line_search))
            call put(indent // 'slack_stiffness = ' // format_real(solver%slack_stiffness))
            call put(indent // 'initial_step = ' // format_real(solver%initial_step))
            call put(indent // 'min_step = ' // format_real(solver%min_step))
            call put(indent // 'max_step = ' // format_real(solver%max_step))
            call put(indent // 'step_growth = ' // format_real(solver%step_growth))
            call put(indent // 'step_cut = ' // format_real(solver%step_cut))
            call put(indent // 'easy_iterations = ' // format_integer(solver%easy_iterations))
            call put(indent // 'max_step_cuts = ' // format_integer(solver%max_step_cuts))
            call put(indent // 'scheme = ' // quote_string(solver%scheme))
            call put(indent // 'max_friction_iterations = ' &
                // format_integer(solver%max_friction_iterations))
            call put(indent // 'min_length_ratio = ' // format_real(solver%min_length_ratio))
            call put(indent // 'friction_tolerance = ' // format_real(solver%friction_tolerance))
            call put('/')
        end associate

        if (allocated(config%materials)) then
            do k = 1, size(config%materials)
                associate(material => config%materials(k))
                    call put('&material')
                    call put(indent // 'name = ' // quote_string(material%name))
                    call put(indent // 'law = ' // quote_string(material%law))
                    call put(indent // 'stiffness = ' // format_real(material%stiffness))
                    call put(indent // 'modulus = ' // format_real(material%modulus))
                    call put(indent // 'area = ' // format_real(material%area))
                    call put(indent // 'table_file = ' // quote_string(material%table_file))
                    call put(indent // 'prestress = ' // format_real(material%prestress))
                    call put('/')
                end associate
            end do
        end if

        if (allocated(config%contacts)) then
            do k = 1, size(config%contacts)
                associate(contact => config%contacts(k))
                    call put('&contact')
                    call put(indent // 'materials = ' // quote_string(contact%materials(1)) &
                        // ', ' // quote_string(contact%materials(2)))
                    call put(indent // 'law = ' // quote_string(contact%law))
                    call put(indent // 'friction_coefficient = ' &
                        // format_real(contact%friction_coefficient))
                    call put(indent // 'adhesion = ' // format_real(contact%adhesion))
                    call put(indent // 'decay_start = ' // format_real(contact%decay_start))
                    call put(indent // 'decay_end = ' // format_real(contact%decay_end))
                    call put('/')
                end associate
            end do
        end if

        if (len_trim(config%fabric%kind) > 0) then
            call put_fabric()
        else
            call put_network()
        end if

        if (allocated(config%path%time)) then
            call put('&path')
            call put_reals('time', config%path%time)
            if (allocated(config%path%p_force)) call put_reals('p_force', config%path%p_force)
            if (allocated(config%path%p_disp)) call put_reals('p_disp', config%path%p_disp)
            call put('/')
        end if

        associate(output => config%output)
            call put('&output')
            call put(indent // 'folder = ' // quote_string(output%folder))
            call put(indent // 'vtk_every = ' // format_integer(output%vtk_every))
            call put(indent // 'vtk_format = ' // quote_string(output%vtk_format))
            call put(indent // 'progress = ' // format_logical(output%progress))
            call put(indent // 'residual_history = ' // format_logical(output%residual_history))
            call put('/')
        end associate
        if (present(status)) status = stat

    contains


        !> The &fabric group (its generator makes the nodes, yarns and supports).
        subroutine put_fabric()
            associate(fabric => config%fabric)
                call put('&fabric')
                call put(indent // 'kind = ' // quote_string(fabric%kind))
                call put(indent // 'cells = ' // format_integer(fabric%cells(1)) // ', ' &
                    // format_integer(fabric%cells(2)))
                call put(indent // 'spacing = ' // reals(fabric%spacing))
                call put(indent // 'boundary = ' // quote_string(fabric%boundary))
                call put(indent // 'strain = ' // format_real(fabric%strain))
                call put(indent // 'lateral_strain = ' // format_real(fabric%lateral_strain))
                call put(indent // 'sides = ' // quote_string(fabric%sides))
                call put(indent // 'elements_per_segment = ' &
                    // format_integer(fabric%elements_per_segment))
                call put(indent // 'knit_material = ' // quote_string(fabric%knit_material))
                call put(indent // 'inlay_material = ' // quote_string(fabric%inlay_material))
                call put(indent // 'head_width = ' // format_real(fabric%head_width))
                call put(indent // 'inlay_offset = ' // format_real(fabric%inlay_offset))
                call put(indent // 'inlay_every = ' // format_integer(fabric%inlay_every))
                call put(indent // 'warp_material = ' // quote_string(fabric%warp_material))
                call put(indent // 'weft_material = ' // quote_string(fabric%weft_material))
                call put(indent // 'gap = ' // format_real(fabric%gap))
                if (size(fabric%gap_factor) > 0) then
                    call put_reals('gap_factor_p_disp', fabric%gap_factor_p_disp)
                    call put_reals('gap_factor', fabric%gap_factor)
                end if
                call put('/')
            end associate
        end subroutine put_fabric

        !> &geometry or &nodes and &yarn, then &support and &load.
        subroutine put_network()
            from_file = len_trim(config%geometry%file) > 0
            call put('&geometry')
            call put(indent // 'file = ' // quote_string(config%geometry%file))
            call put('/')
            if (from_file) then
                call put('! The nodes and yarns are those of the geometry file.')
            else
                if (allocated(config%node_positions)) then
                    call put('&nodes')
                    n = size(config%node_positions, 2)
                    do k = 1, n
                        if (k == 1) then
                            call put(indent // 'xyz = ' // reals(config%node_positions(:, k)))
                        else
                            call put(indent // '      ' // reals(config%node_positions(:, k)))
                        end if
                    end do
                    call put('/')
                end if
                if (allocated(config%yarns)) then
                    do k = 1, size(config%yarns)
                        associate(yarn => config%yarns(k))
                            call put('&yarn')
                            call put(indent // 'material = ' // quote_string(yarn%material))
                            call put(indent // 'elements_per_segment = ' &
                                // format_integer(yarn%elements_per_segment))
                            if (allocated(yarn%nodes)) call put_integers('nodes', yarn%nodes)
                            call put('/')
                        end associate
                    end do
                end if
            end if

            if (allocated(config%supports)) then
                do k = 1, size(config%supports)
                    associate(support => config%supports(k))
                        call put('&support')
                        call put(indent // 'name = ' // quote_string(support%name))
                        call put(indent // 'fix = ' // quote_string(support%fix))
                        call put(indent // 'displacement = ' // reals(support%displacement))
                        if (allocated(support%nodes)) call put_integers('nodes', support%nodes)
                        call put('/')
                    end associate
                end do
            end if

            if (allocated(config%loads)) then
                do k = 1, size(config%loads)
                    associate(load => config%loads(k))
                        call put('&load')
                        call put(indent // 'force = ' // reals(load%force))
                        if (allocated(load%nodes)) call put_integers('nodes', load%nodes)
                        call put('/')
                    end associate
                end do
            end if
        end subroutine put_network


        subroutine put(line)
            character(len=*), intent(in) :: line

            if (stat /= 0) return
            if (present(status)) then
                write(unit, '(a)', iostat=stat, iomsg=iomsg) line
                status = stat
                if (stat /= 0 .and. present(message)) message = iomsg
            else
                write(unit, '(a)') line
            end if
        end subroutine put

        !> `name = v1 v2 ...`, integers_per_line values per line; nothing for no values.
        subroutine put_integers(name, values)
            character(len=*), intent(in) :: name
            integer, intent(in) :: values(:)
            character(len=:), allocatable :: line
            integer :: i

            if (size(values) == 0) return
            line = indent // name // ' ='
            do i = 1, size(values)
                line = line // ' ' // format_integer(values(i))
                if (mod(i, integers_per_line) == 0 .or. i == size(values)) then
                    call put(line)
                    line = indent // repeat(' ', len(name) + 2)
                end if
            end do
        end subroutine put_integers

        !> `name = v1 v2 ...`, reals_per_line values per line; nothing for no values.
        subroutine put_reals(name, values)
            character(len=*), intent(in) :: name
            real(wp), intent(in) :: values(:)
            character(len=:), allocatable :: line
            integer :: i

            if (size(values) == 0) return
            line = indent // name // ' ='
            do i = 1, size(values)
                line = line // ' ' // format_real(values(i))
                if (mod(i, reals_per_line) == 0 .or. i == size(values)) then
                    call put(line)
                    line = indent // repeat(' ', len(name) + 2)
                end if
            end do
        end subroutine put_reals

    end subroutine write_config

    !> Reals separated by blanks.
    function reals(values) result(text)
        real(wp), intent(in) :: values(:)
        character(len=:), allocatable :: text
        integer :: i

        text = ''
        do i = 1, size(values)
            if (i > 1) text = text // ' '
            text = text // format_real(values(i))
        end do
    end function reals

    pure function format_logical(value) result(text)
        logical, intent(in) :: value
        character(len=:), allocatable :: text

        if (value) then
            text = '.true.'
        else
            text = '.false.'
        end if
    end function format_logical

end module yarnfort_input_echo
