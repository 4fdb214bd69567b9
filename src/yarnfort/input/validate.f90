! SPDX-License-Identifier: MIT
!> Checks of a read `config_type` that need no network: known names, positive and finite
!> parameters, node ids in range, no zero-length segments or elements, no two segments
!> joining the same two nodes, consistent supports, loads and load path, known friction
!> laws with their parameters and, when any &contact is given, one for every pair of
!> yarn types that meet. Each message names the group, the variable and the value.
module yarnfort_input_validate
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use, intrinsic :: iso_fortran_env, only: int64
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_input_config, only: config_type, solver_config_type, output_config_type, &
        material_config_type, path_config_type, contact_config_type, name_length, &
        solver_presets
    use yarnfort_input_text, only: format_integer, format_real, join_names, closest_name
    implicit none
    private

    public :: check_config, coincidence_tolerance, known_laws, known_linear_solvers
    public :: known_contact_laws, known_schemes

    !> A segment between consecutive yarn nodes is of zero length when it is not longer
    !> than this times the diagonal of the box around all nodes.
    real(wp), parameter :: coincidence_tolerance = 100 * epsilon(1.0_wp)
    !> Smallest &solver min_step as a fraction of the largest |&path time|: a shorter
    !> step would not (or barely) change the pseudo-time, and the continuation would stall.
    real(wp), parameter :: time_resolution = 100 * epsilon(1.0_wp)
    !> Largest network the solver indexes with default integers: 3 unknowns per node and
    !> a 6 x 6 Jacobian block per element (elements_per_segment multiplies both).
    integer, parameter :: max_network_nodes = huge(1) / 3
    integer, parameter :: max_network_elements = huge(1) / 36
    !> Values of &material law.
    character(len=*), parameter :: known_laws(*) = [character(len=11) :: 'linear', &
        'neo_hookean', 'table']
    !> Values of &solver linear_solver.
    character(len=*), parameter :: known_linear_solvers(*) = [character(len=11) :: 'auto', &
        'umfpack', 'klu', 'cholmod', 'cholmod+klu', 'dense']
    !> Values of &contact law.
    character(len=*), parameter :: known_contact_laws(*) = [character(len=17) :: 'bonded', &
        'coulomb', 'adhesion', 'decaying_adhesion']
    !> Values of &solver scheme.
    character(len=*), parameter :: known_schemes(*) = [character(len=10) :: 'monolithic', &
        'staggered']
    character(len=1), parameter :: axis(3) = ['x', 'y', 'z']
    !> Characters of material and support names.
    character(len=*), parameter :: name_characters = &
        'abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-.'

contains

    !> Check everything that can be checked before the network is built.
    subroutine check_config(config, error)
        type(config_type), intent(in) :: config
        type(error_type), allocatable, intent(out) :: error
        integer, allocatable :: owner(:, :)

        call require_at_least(error, '&control', 'max_steps', config%control%max_steps, 0)
        if (allocated(error)) return
        call check_solver(config%solver, error)
        if (allocated(error)) return
        call check_output(config%output, error)
        if (allocated(error)) return
        call check_materials(config%materials, error)
        if (allocated(error)) return
        call check_nodes(config, error)
        if (allocated(error)) return
        call check_yarns(config, error)
        if (allocated(error)) return
        call check_duplicate_segments(config, error)
        if (allocated(error)) return
        call check_contacts(config, error)
        if (allocated(error)) return
        call check_supports(config, owner, error)
        if (allocated(error)) return
        call check_loads(config, owner, error)
        if (allocated(error)) return
        call check_path(config%path, error)
        if (allocated(error)) return
        call check_step_resolution(config%solver, config%path, error)
    end subroutine check_config

    subroutine check_solver(solver, error)
        type(solver_config_type), intent(in) :: solver
        type(error_type), allocatable, intent(out) :: error

        if (.not. any(solver_presets == solver%preset)) then
            call fatal_error(error, "&solver: preset = '" // trim(solver%preset) &
                // "' is unknown (use " // join_names(solver_presets, '') // ')' &
                // suggestion(solver%preset, solver_presets))
            return
        end if
        if (.not. any(known_linear_solvers == solver%linear_solver)) then
            call fatal_error(error, "&solver: linear_solver = '" // trim(solver%linear_solver) &
                // "' is unknown (use " // join_names(known_linear_solvers, '') // ')')
            return
        end if
        call require_positive(error, '&solver', 'residual_tolerance', solver%residual_tolerance)
        if (allocated(error)) return
        call require_positive(error, '&solver', 'step_tolerance', solver%step_tolerance)
        if (allocated(error)) return
        call require_at_least(error, '&solver', 'max_iterations', solver%max_iterations, 1)
        if (allocated(error)) return
        call require_at_least(error, '&solver', 'max_setup_calls', solver%max_setup_calls, 1)
        if (allocated(error)) return
        call require_at_least(error, '&solver', 'easy_iterations', solver%easy_iterations, 0)
        if (allocated(error)) return
        call require_at_least(error, '&solver', 'max_step_cuts', solver%max_step_cuts, 0)
        if (allocated(error)) return
        if (.not. ieee_is_finite(solver%slack_stiffness)) then
            call not_finite(error, '&solver', 'slack_stiffness', solver%slack_stiffness)
            return
        end if
        if (solver%slack_stiffness < 0.0_wp) then
            call fatal_error(error, '&solver: slack_stiffness = ' &
                // format_real(solver%slack_stiffness) // ' must be >= 0')
            return
        end if
        call require_positive(error, '&solver', 'min_step', solver%min_step)
        if (allocated(error)) return
        call require_positive(error, '&solver', 'initial_step', solver%initial_step)
        if (allocated(error)) return
        call require_positive(error, '&solver', 'max_step', solver%max_step)
        if (allocated(error)) return
        if (solver%min_step > solver%max_step) then
            call fatal_error(error, '&solver: min_step = ' // format_real(solver%min_step) &
                // ' is larger than max_step = ' // format_real(solver%max_step))
            return
        end if
        ! An initial_step above max_step is simply capped at max_step by the continuation.
        if (solver%initial_step < solver%min_step) then
            call fatal_error(error, '&solver: initial_step = ' &
                // format_real(solver%initial_step) // ' is smaller than min_step = ' &
                // format_real(solver%min_step))
            return
        end if
        if (.not. ieee_is_finite(solver%step_cut)) then
            call not_finite(error, '&solver', 'step_cut', solver%step_cut)
            return
        end if
        if (solver%step_cut <= 0.0_wp .or. solver%step_cut >= 1.0_wp) then
            call fatal_error(error, '&solver: step_cut = ' // format_real(solver%step_cut) &
                // ' must lie strictly between 0 and 1')
            return
        end if
        if (.not. ieee_is_finite(solver%step_growth)) then
            call not_finite(error, '&solver', 'step_growth', solver%step_growth)
            return
        end if
        if (solver%step_growth < 1.0_wp) then
            call fatal_error(error, '&solver: step_growth = ' // format_real(solver%step_growth) &
                // ' must be >= 1')
            return
        end if
        if (.not. any(known_schemes == solver%scheme)) then
            call fatal_error(error, "&solver: scheme = '" // trim(solver%scheme) &
                // "' is unknown (use " // join_names(known_schemes, '') // ')' &
                // suggestion(solver%scheme, known_schemes))
            return
        end if
        call require_at_least(error, '&solver', 'max_friction_iterations', &
            solver%max_friction_iterations, 1)
        if (allocated(error)) return
        if (.not. ieee_is_finite(solver%min_length_ratio)) then
            call not_finite(error, '&solver', 'min_length_ratio', solver%min_length_ratio)
            return
        end if
        if (solver%min_length_ratio <= 0.0_wp .or. solver%min_length_ratio >= 1.0_wp) then
            call fatal_error(error, '&solver: min_length_ratio = ' &
                // format_real(solver%min_length_ratio) // ' must lie strictly between 0 and 1')
            return
        end if
        call require_positive(error, '&solver', 'friction_tolerance', solver%friction_tolerance)
    end subroutine check_solver

    subroutine check_output(output, error)
        type(output_config_type), intent(in) :: output
        type(error_type), allocatable, intent(out) :: error

        if (len_trim(output%folder) == 0) then
            call fatal_error(error, "&output: folder = '' is empty (give a folder name)")
            return
        end if
        call require_at_least(error, '&output', 'vtk_every', output%vtk_every, 0)
        if (allocated(error)) return
        if (output%vtk_format /= 'binary' .and. output%vtk_format /= 'ascii') then
            call fatal_error(error, "&output: vtk_format = '" // trim(output%vtk_format) &
                // "' is unknown (use 'binary' or 'ascii')")
            return
        end if
    end subroutine check_output

    subroutine check_materials(materials, error)
        type(material_config_type), intent(in), allocatable :: materials(:)
        type(error_type), allocatable, intent(out) :: error
        type(material_config_type) :: unset
        integer :: m, other
        character(len=:), allocatable :: label

        if (.not. allocated(materials)) then
            call fatal_error(error, 'no &material group: at least one material is needed')
            return
        end if
        if (size(materials) == 0) then
            call fatal_error(error, 'no &material group: at least one material is needed')
            return
        end if
        do m = 1, size(materials)
            associate(material => materials(m))
                label = '&material #' // format_integer(m)
                if (len_trim(material%name) == 0) then
                    call fatal_error(error, label // ': name is empty')
                    return
                end if
                call check_name(error, label, material%name)
                if (allocated(error)) return
                label = "&material '" // trim(material%name) // "'"
                do other = 1, m - 1
                    if (materials(other)%name == material%name) then
                        call fatal_error(error, "&material: name = '" // trim(material%name) &
                            // "' is defined twice (&material #" // format_integer(other) &
                            // ' and #' // format_integer(m) // ')')
                        return
                    end if
                end do
                select case (trim(material%law))
                case ('')
                    call fatal_error(error, label // ": law is not set (use " &
                        // join_names(known_laws, '') // ')')
                case ('linear')
                    call require_parameter(error, label, 'stiffness', material%stiffness, &
                        unset%stiffness, 'linear')
                    if (allocated(error)) return
                    call forbid_parameter(error, label, 'modulus', material%modulus, &
                        unset%modulus, 'linear')
                    if (allocated(error)) return
                    call forbid_parameter(error, label, 'area', material%area, unset%area, &
                        'linear')
                    if (allocated(error)) return
                    call forbid_table(error, label, material%table_file, 'linear')
                case ('neo_hookean')
                    call require_parameter(error, label, 'modulus', material%modulus, &
                        unset%modulus, 'neo_hookean')
                    if (allocated(error)) return
                    call require_parameter(error, label, 'area', material%area, unset%area, &
                        'neo_hookean')
                    if (allocated(error)) return
                    call forbid_parameter(error, label, 'stiffness', material%stiffness, &
                        unset%stiffness, 'neo_hookean')
                    if (allocated(error)) return
                    call forbid_table(error, label, material%table_file, 'neo_hookean')
                case ('table')
                    if (len_trim(material%table_file) == 0) then
                        call fatal_error(error, label // ": table_file is not set (law " &
                            // "'table' needs a CSV file of strain, force)")
                        return
                    end if
                    call forbid_parameter(error, label, 'stiffness', material%stiffness, &
                        unset%stiffness, 'table')
                    if (allocated(error)) return
                    call forbid_parameter(error, label, 'modulus', material%modulus, &
                        unset%modulus, 'table')
                    if (allocated(error)) return
                    call forbid_parameter(error, label, 'area', material%area, unset%area, &
                        'table')
                case default
                    call fatal_error(error, label // ": law = '" // trim(material%law) &
                        // "' is unknown (use " // join_names(known_laws, '') // ')')
                end select
                if (allocated(error)) return
                if (.not. (material%prestress >= 0.0_wp .and. &
                        material%prestress < huge(1.0_wp))) then
                    call fatal_error(error, label // ': prestress = ' &
                        // format_real(material%prestress) &
                        // ' must be a tension >= 0 (N)')
                    return
                end if
            end associate
        end do
    end subroutine check_materials

    !> Contacts: two defined materials, one group per unordered pair, a known friction law
    !> with exactly its parameters; and, when any &contact is given, one for every pair
    !> of yarn types that meet at a node.
    subroutine check_contacts(config, error)
        type(config_type), intent(in) :: config
        type(error_type), allocatable, intent(out) :: error
        character(len=name_length), allocatable :: material_names(:)
        !> `pair(a, b)`: the &contact of materials a and b (symmetric), or 0.
        integer, allocatable :: pair(:, :)
        integer :: c, i, a, b
        character(len=:), allocatable :: label

        if (.not. allocated(config%contacts)) return
        if (size(config%contacts) == 0) return
        material_names = config%materials%name
        allocate(pair(size(material_names), size(material_names)), source=0)
        do c = 1, size(config%contacts)
            associate(contact => config%contacts(c))
                label = '&contact #' // format_integer(c)
                do i = 1, 2
                    call check_contact_material(error, label, i, contact%materials(i), &
                        material_names)
                    if (allocated(error)) return
                end do
                a = findloc(material_names, contact%materials(1), dim=1)
                b = findloc(material_names, contact%materials(2), dim=1)
                label = label // ' (' // pair_text(contact) // ')'
                if (pair(a, b) /= 0) then
                    call fatal_error(error, '&contact #' // format_integer(c) &
                        // ': materials = ' // pair_text(contact) // ' is the same pair as ' &
                        // '&contact #' // format_integer(pair(a, b)) // ' (materials = ' &
                        // pair_text(config%contacts(pair(a, b))) // '; the order does not ' &
                        // 'matter): give one &contact per pair of yarn types')
                    return
                end if
                pair(a, b) = c
                pair(b, a) = c
                call check_contact_law(error, label, contact)
                if (allocated(error)) return
            end associate
        end do
        call check_contacts_complete(config, pair, error)
    end subroutine check_contacts

    !> 'a', 'b' of a contact, as in its materials variable.
    pure function pair_text(contact) result(text)
        type(contact_config_type), intent(in) :: contact
        character(len=:), allocatable :: text

        text = quoted_list(contact%materials)
    end function pair_text

    !> materials(i) of a &contact: set, and the name of a &material.
    subroutine check_contact_material(error, label, i, name, material_names)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: label, name
        integer, intent(in) :: i
        character(len=*), intent(in) :: material_names(:)
        character(len=:), allocatable :: variable

        variable = 'materials(' // format_integer(i) // ')'
        if (len_trim(name) == 0) then
            call fatal_error(error, label // ': ' // variable // ' is not set (give the ' &
                // "two yarn types, e.g. materials = '" // trim(material_names(1)) // "', '" &
                // trim(material_names(size(material_names))) // "')")
            return
        end if
        if (.not. any(material_names == name)) then
            call fatal_error(error, label // ': ' // variable // " = '" // trim(name) &
                // "' is not defined by any &material (defined: " &
                // quoted_list(material_names) // ')' // suggestion(name, material_names))
        end if
    end subroutine check_contact_material

    !> A known friction law with its own parameters only: all of them finite and >= 0,
    !> and decay_start < decay_end.
    subroutine check_contact_law(error, label, contact)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: label
        type(contact_config_type), intent(in) :: contact
        type(contact_config_type) :: unset
        character(len=*), parameter :: variables(4) = [character(len=20) :: &
            'friction_coefficient', 'adhesion', 'decay_start', 'decay_end']
        logical :: needed(4)
        real(wp) :: values(4), unset_values(4)
        integer :: i

        select case (trim(contact%law))
        case ('')
            call fatal_error(error, label // ': law is not set (use ' &
                // join_names(known_contact_laws, '') // ')')
            return
        case ('bonded')
            needed = [.false., .false., .false., .false.]
        case ('coulomb')
            needed = [.true., .false., .false., .false.]
        case ('adhesion')
            needed = [.true., .true., .false., .false.]
        case ('decaying_adhesion')
            needed = [.true., .true., .true., .true.]
        case default
            call fatal_error(error, label // ": law = '" // trim(contact%law) &
                // "' is unknown (use " // join_names(known_contact_laws, '') // ')' &
                // suggestion(contact%law, known_contact_laws))
            return
        end select
        values = [contact%friction_coefficient, contact%adhesion, contact%decay_start, &
            contact%decay_end]
        unset_values = [unset%friction_coefficient, unset%adhesion, unset%decay_start, &
            unset%decay_end]
        do i = 1, size(variables)
            if (needed(i)) then
                call require_nonnegative_parameter(error, label, trim(variables(i)), &
                    values(i), unset_values(i), trim(contact%law))
            else
                call forbid_parameter(error, label, trim(variables(i)), values(i), &
                    unset_values(i), trim(contact%law))
            end if
            if (allocated(error)) return
        end do
        if (needed(3) .and. needed(4)) then
            if (.not. (contact%decay_start < contact%decay_end)) then
                call fatal_error(error, label // ': decay_start = ' &
                    // format_real(contact%decay_start) // ' must be less than decay_end = ' &
                    // format_real(contact%decay_end) // ' (the adhesion decays from ' &
                    // 'tension decay_start to decay_end)')
                return
            end if
        end if
    end subroutine check_contact_law

    !> With any &contact, every pair of yarn types meeting at a node needs one. A node
    !> meets when two different yarns list it (yarns of two types, or two of one type).
    subroutine check_contacts_complete(config, pair, error)
        type(config_type), intent(in) :: config
        integer, intent(in) :: pair(:, :)
        type(error_type), allocatable, intent(out) :: error
        integer, allocatable :: material_of(:), first(:), yarns_at(:), last_yarn(:), filled(:)
        integer :: n_nodes, y, i, node, j, k, a, b

        n_nodes = size(config%node_positions, 2)
        allocate(material_of(size(config%yarns)))
        do y = 1, size(config%yarns)
            material_of(y) = findloc(config%materials%name, config%yarns(y)%material, dim=1)
        end do
        ! Yarns through each node, each once (a yarn may list a node twice): the yarns
        ! at node n are yarns_at(first(n):first(n + 1) - 1).
        allocate(first(n_nodes + 1), source=0)
        allocate(last_yarn(n_nodes), source=0)
        do y = 1, size(config%yarns)
            do i = 1, size(config%yarns(y)%nodes)
                node = config%yarns(y)%nodes(i)
                if (last_yarn(node) == y) cycle
                last_yarn(node) = y
                first(node + 1) = first(node + 1) + 1
            end do
        end do
        first(1) = 1
        do node = 1, n_nodes
            first(node + 1) = first(node + 1) + first(node)
        end do
        allocate(yarns_at(first(n_nodes + 1) - 1))
        allocate(filled(n_nodes), source=0)
        last_yarn = 0
        do y = 1, size(config%yarns)
            do i = 1, size(config%yarns(y)%nodes)
                node = config%yarns(y)%nodes(i)
                if (last_yarn(node) == y) cycle
                last_yarn(node) = y
                yarns_at(first(node) + filled(node)) = y
                filled(node) = filled(node) + 1
            end do
        end do
        do node = 1, n_nodes
            do j = first(node), first(node + 1) - 1
                do k = j + 1, first(node + 1) - 1
                    a = material_of(yarns_at(j))
                    b = material_of(yarns_at(k))
                    if (pair(a, b) /= 0) cycle
                    call fatal_error(error, "no &contact for yarn types '" &
                        // trim(config%materials(a)%name) // "' and '" &
                        // trim(config%materials(b)%name) // "' (they meet at node " &
                        // format_integer(node) // '); ' // yarn_label(config, yarns_at(j)) &
                        // ' and ' // yarn_label(config, yarns_at(k)) // ' share it, and ' &
                        // 'with any &contact group every pair of yarn types that meet ' &
                        // 'needs one')
                    return
                end do
            end do
        end do
    end subroutine check_contacts_complete

    !> Names are single words (the geometry file and the curve CSV header use them).
    subroutine check_name(error, label, name)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: label, name

        if (verify(trim(name), name_characters) > 0) then
            call fatal_error(error, label // ": name = '" // trim(name) // "' may contain " &
                // "only letters, digits, '_', '-' and '.'")
        end if
    end subroutine check_name

    !> A law parameter must be set, positive and finite.
    subroutine require_parameter(error, label, variable, value, unset, law)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: label, variable, law
        real(wp), intent(in) :: value, unset

        if (value == unset) then
            call fatal_error(error, label // ': ' // variable // " is not set (law '" // law &
                // "' needs it)")
            return
        end if
        call require_positive(error, label, variable, value)
    end subroutine require_parameter

    !> A parameter another law uses must stay unset (a silently ignored value is a mistake).
    subroutine forbid_parameter(error, label, variable, value, unset, law)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: label, variable, law
        real(wp), intent(in) :: value, unset

        if (.not. (value == unset)) then
            call fatal_error(error, label // ': ' // variable // ' = ' // format_real(value) &
                // " is not used by law '" // law // "' (remove it)")
        end if
    end subroutine forbid_parameter

    subroutine forbid_table(error, label, table_file, law)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: label, table_file, law

        if (len_trim(table_file) > 0) then
            call fatal_error(error, label // ": table_file = '" // trim(table_file) &
                // "' is not used by law '" // law // "' (remove it)")
        end if
    end subroutine forbid_table

    subroutine check_nodes(config, error)
        type(config_type), intent(in) :: config
        type(error_type), allocatable, intent(out) :: error
        integer :: n, k

        if (.not. allocated(config%node_positions)) then
            call fatal_error(error, "no nodes: give &nodes xyz = ... / or &geometry file = " &
                // "'...' /")
            return
        end if
        if (size(config%node_positions, 2) == 0) then
            call fatal_error(error, "no nodes: give &nodes xyz = ... / or &geometry file = " &
                // "'...' /")
            return
        end if
        do n = 1, size(config%node_positions, 2)
            do k = 1, 3
                if (ieee_is_finite(config%node_positions(k, n))) cycle
                if (len_trim(config%geometry%file) > 0) then
                    call fatal_error(error, "&geometry: file '" &
                        // trim(config%geometry%file) // "': node " // format_integer(n) &
                        // ' ' // axis(k) // ' = ' // format_real(config%node_positions(k, n)) &
                        // ' is not finite')
                else
                    call fatal_error(error, '&nodes: xyz(' // format_integer(3 * (n - 1) + k) &
                        // ') = ' // format_real(config%node_positions(k, n)) // ' (node ' &
                        // format_integer(n) // ' ' // axis(k) // ') is not finite')
                end if
                return
            end do
        end do
    end subroutine check_nodes

    !> '&yarn #k', or 'yarn #k of the geometry file' when the yarns come from a file.
    function yarn_label(config, k) result(label)
        type(config_type), intent(in) :: config
        integer, intent(in) :: k
        character(len=:), allocatable :: label

        if (len_trim(config%geometry%file) > 0) then
            label = 'yarn #' // format_integer(k) // " of &geometry file '" &
                // trim(config%geometry%file) // "'"
        else
            label = '&yarn #' // format_integer(k)
        end if
    end function yarn_label

    subroutine check_yarns(config, error)
        type(config_type), intent(in) :: config
        type(error_type), allocatable, intent(out) :: error
        integer :: y, i, n_nodes, a, b
        !> Elements and new nodes of the yarns so far (elements_per_segment may be large).
        integer(int64) :: n_elements, n_new_nodes
        logical, allocatable :: used(:)
        real(wp) :: scale, length
        character(len=:), allocatable :: label, guess
        character(len=name_length), allocatable :: material_names(:)
        character(len=80) :: counts

        if (.not. allocated(config%yarns)) then
            call fatal_error(error, 'no yarns: give &yarn groups or yarn lines in the ' &
                // '&geometry file')
            return
        end if
        if (size(config%yarns) == 0) then
            call fatal_error(error, 'no yarns: give &yarn groups or yarn lines in the ' &
                // '&geometry file')
            return
        end if
        material_names = config%materials%name
        n_nodes = size(config%node_positions, 2)
        scale = norm2(maxval(config%node_positions, dim=2) - minval(config%node_positions, dim=2))
        allocate(used(n_nodes), source=.false.)
        n_elements = 0
        n_new_nodes = 0
        do y = 1, size(config%yarns)
            associate(yarn => config%yarns(y))
                label = yarn_label(config, y)
                if (len_trim(yarn%material) == 0) then
                    call fatal_error(error, label // ': material is not set')
                    return
                end if
                if (.not. any(material_names == yarn%material)) then
                    guess = closest_name(trim(yarn%material), material_names)
                    if (len(guess) > 0) guess = "; did you mean '" // guess // "'?"
                    call fatal_error(error, label // ": material = '" // trim(yarn%material) &
                        // "' is not defined by any &material (defined: " &
                        // quoted_list(material_names) // ')' // guess)
                    return
                end if
                if (yarn%elements_per_segment < 1) then
                    call fatal_error(error, label // ': elements_per_segment = ' &
                        // format_integer(yarn%elements_per_segment) // ' must be >= 1')
                    return
                end if
                if (size(yarn%nodes) < 2) then
                    call fatal_error(error, label // ': nodes has ' &
                        // format_integer(size(yarn%nodes)) &
                        // ' node id(s); a yarn needs at least 2')
                    return
                end if
                n_elements = n_elements + (size(yarn%nodes) - 1) &
                    * int(yarn%elements_per_segment, int64)
                n_new_nodes = n_new_nodes + (size(yarn%nodes) - 1) &
                    * (int(yarn%elements_per_segment, int64) - 1)
                if (n_elements > max_network_elements &
                    .or. n_nodes + n_new_nodes > max_network_nodes) then
                    write(counts, '(i0, " elements and ", i0, " nodes")') n_elements, &
                        n_nodes + n_new_nodes
                    call fatal_error(error, label // ': elements_per_segment = ' &
                        // format_integer(yarn%elements_per_segment) // ' makes the network ' &
                        // trim(counts) // ' (with the yarns before it); at most ' &
                        // format_integer(max_network_elements) // ' elements and ' &
                        // format_integer(max_network_nodes) // ' nodes fit the solver')
                    return
                end if
                do i = 1, size(yarn%nodes)
                    call require_node(error, label, 'nodes', i, yarn%nodes(i), n_nodes)
                    if (allocated(error)) return
                    used(yarn%nodes(i)) = .true.
                end do
                do i = 1, size(yarn%nodes) - 1
                    a = yarn%nodes(i)
                    b = yarn%nodes(i + 1)
                    if (a == b) then
                        call fatal_error(error, label // ': nodes(' // format_integer(i) &
                            // ') = nodes(' // format_integer(i + 1) // ') = ' &
                            // format_integer(a) // ': zero-length segment')
                        return
                    end if
                    length = norm2(config%node_positions(:, b) - config%node_positions(:, a))
                    if (length <= coincidence_tolerance * scale) then
                        call fatal_error(error, label // ': nodes ' // format_integer(a) &
                            // ' and ' // format_integer(b) // ' (nodes(' // format_integer(i) &
                            // ') and nodes(' // format_integer(i + 1) // ')) are at the ' &
                            // 'same position (' // format_position(config%node_positions(:, a)) &
                            // '): zero-length element')
                        return
                    end if
                end do
            end associate
        end do
        do i = 1, n_nodes
            if (.not. used(i)) then
                call fatal_error(error, node_source(config) // ': node ' // format_integer(i) &
                    // ' is on no yarn (a node off all yarns has no stiffness)')
                return
            end if
        end do
    end subroutine check_yarns

    !> No two segments, of one yarn or of two, join the same two nodes: their elements
    !> would lie on top of each other (a yarn doubling back, or a yarn listed twice).
    !> Segments are bucketed by their lower node id, so the check is linear in their number.
    subroutine check_duplicate_segments(config, error)
        type(config_type), intent(in) :: config
        type(error_type), allocatable, intent(out) :: error
        !> The segments whose lower node is `a` are slots first(a):first(a + 1) - 1, each
        !> with its yarn and its position i in the yarn (nodes(i), nodes(i + 1)).
        integer, allocatable :: first(:), filled(:), yarn_of(:), position_of(:)
        !> `seen(b)`: the last slot met with upper node b (a slot of the current lower
        !> node when it is >= first(a)).
        integer, allocatable :: seen(:)
        integer :: n_nodes, y, i, a, b, k, slot

        n_nodes = size(config%node_positions, 2)
        allocate(first(n_nodes + 1), source=0)
        do y = 1, size(config%yarns)
            associate(nodes => config%yarns(y)%nodes)
                do i = 1, size(nodes) - 1
                    a = min(nodes(i), nodes(i + 1))
                    first(a + 1) = first(a + 1) + 1
                end do
            end associate
        end do
        first(1) = 1
        do a = 1, n_nodes
            first(a + 1) = first(a + 1) + first(a)
        end do
        allocate(yarn_of(first(n_nodes + 1) - 1), position_of(first(n_nodes + 1) - 1))
        allocate(filled(n_nodes), source=0)
        do y = 1, size(config%yarns)
            associate(nodes => config%yarns(y)%nodes)
                do i = 1, size(nodes) - 1
                    a = min(nodes(i), nodes(i + 1))
                    slot = first(a) + filled(a)
                    yarn_of(slot) = y
                    position_of(slot) = i
                    filled(a) = filled(a) + 1
                end do
            end associate
        end do
        allocate(seen(n_nodes), source=0)
        do a = 1, n_nodes
            do k = first(a), first(a + 1) - 1
                b = upper_node(k)
                if (seen(b) >= first(a)) then
                    call fatal_error(error, segment_text(k) // ' join the same two nodes as ' &
                        // segment_text(seen(b)) // ': duplicate segment (two strings ' &
                        // 'between one pair of nodes would lie on top of each other)')
                    return
                end if
                seen(b) = k
            end do
        end do

    contains

        integer function upper_node(slot)
            integer, intent(in) :: slot

            associate(nodes => config%yarns(yarn_of(slot))%nodes, i => position_of(slot))
                upper_node = max(nodes(i), nodes(i + 1))
            end associate
        end function upper_node

        !> "&yarn #2: nodes(3), nodes(4) = 5, 2"
        function segment_text(slot) result(text)
            integer, intent(in) :: slot
            character(len=:), allocatable :: text

            associate(nodes => config%yarns(yarn_of(slot))%nodes, i => position_of(slot))
                text = yarn_label(config, yarn_of(slot)) // ': nodes(' // format_integer(i) &
                    // '), nodes(' // format_integer(i + 1) // ') = ' &
                    // format_integer(nodes(i)) // ', ' // format_integer(nodes(i + 1))
            end associate
        end function segment_text

    end subroutine check_duplicate_segments

    !> Where the nodes come from, for messages.
    function node_source(config) result(source)
        type(config_type), intent(in) :: config
        character(len=:), allocatable :: source

        if (len_trim(config%geometry%file) > 0) then
            source = "&geometry: file '" // trim(config%geometry%file) // "'"
        else
            source = '&nodes'
        end if
    end function node_source

    !> Supports: names, fix letters, node ids, and at most one support per coordinate
    !> (`owner(k, node)` is the support prescribing component k of node, or 0).
    subroutine check_supports(config, owner, error)
        type(config_type), intent(in) :: config
        integer, allocatable, intent(out) :: owner(:, :)
        type(error_type), allocatable, intent(out) :: error
        integer :: s, other, i, k, n_nodes, node
        character(len=:), allocatable :: label

        n_nodes = size(config%node_positions, 2)
        allocate(owner(3, n_nodes), source=0)
        if (.not. allocated(config%supports)) return
        do s = 1, size(config%supports)
            associate(support => config%supports(s))
                label = '&support #' // format_integer(s)
                if (len_trim(support%name) == 0) then
                    call fatal_error(error, label // ': name is empty (give each support a name)')
                    return
                end if
                call check_name(error, label, support%name)
                if (allocated(error)) return
                label = "&support '" // trim(support%name) // "'"
                do other = 1, s - 1
                    if (config%supports(other)%name == support%name) then
                        call fatal_error(error, "&support: name = '" // trim(support%name) &
                            // "' is used twice (&support #" // format_integer(other) &
                            // ' and #' // format_integer(s) // ')')
                        return
                    end if
                end do
                call check_fix(error, label, support%fix)
                if (allocated(error)) return
                do k = 1, 3
                    if (.not. ieee_is_finite(support%displacement(k))) then
                        call not_finite(error, label, 'displacement(' // format_integer(k) &
                            // ')', support%displacement(k))
                        return
                    end if
                    if (support%displacement(k) /= 0.0_wp &
                        .and. index(support%fix, axis(k)) == 0) then
                        call fatal_error(error, label // ': displacement(' &
                            // format_integer(k) // ') = ' &
                            // format_real(support%displacement(k)) // ' but ' // axis(k) &
                            // " is not in fix = '" // trim(support%fix) &
                            // "' (it would be ignored)")
                        return
                    end if
                end do
                call check_node_list(error, label, support%nodes, n_nodes)
                if (allocated(error)) return
                do i = 1, size(support%nodes)
                    node = support%nodes(i)
                    do k = 1, 3
                        if (index(support%fix, axis(k)) == 0) cycle
                        if (owner(k, node) /= 0) then
                            call fatal_error(error, label // ': node ' // format_integer(node) &
                                // ' ' // axis(k) // " is already prescribed by &support '" &
                                // trim(config%supports(owner(k, node))%name) // "'")
                            return
                        end if
                        owner(k, node) = s
                    end do
                end do
            end associate
        end do
    end subroutine check_supports

    !> fix: one or more of 'x', 'y', 'z', each at most once.
    subroutine check_fix(error, label, fix)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: label, fix
        integer :: i

        if (len_trim(fix) == 0) then
            call fatal_error(error, label // ": fix = '' prescribes nothing (use any of x, y, z)")
            return
        end if
        do i = 1, len_trim(fix)
            if (index('xyz', fix(i:i)) == 0) then
                call fatal_error(error, label // ": fix = '" // trim(fix) // "' has '" &
                    // fix(i:i) // "' (use any of x, y, z)")
                return
            end if
            if (index(fix(:i - 1), fix(i:i)) > 0) then
                call fatal_error(error, label // ": fix = '" // trim(fix) // "' has '" &
                    // fix(i:i) // "' twice")
                return
            end if
        end do
    end subroutine check_fix

    !> Loads: node ids, finite forces, no force on a prescribed coordinate.
    subroutine check_loads(config, owner, error)
        type(config_type), intent(in) :: config
        integer, intent(in) :: owner(:, :)
        type(error_type), allocatable, intent(out) :: error
        integer :: l, i, k, node
        character(len=:), allocatable :: label

        if (.not. allocated(config%loads)) return
        do l = 1, size(config%loads)
            associate(load => config%loads(l))
                label = '&load #' // format_integer(l)
                do k = 1, 3
                    if (.not. ieee_is_finite(load%force(k))) then
                        call not_finite(error, label, 'force(' // format_integer(k) // ')', &
                            load%force(k))
                        return
                    end if
                end do
                call check_node_list(error, label, load%nodes, size(config%node_positions, 2))
                if (allocated(error)) return
                do i = 1, size(load%nodes)
                    node = load%nodes(i)
                    do k = 1, 3
                        if (load%force(k) == 0.0_wp .or. owner(k, node) == 0) cycle
                        call fatal_error(error, label // ': node ' // format_integer(node) &
                            // ' has force(' // format_integer(k) // ') = ' &
                            // format_real(load%force(k)) // ' but its ' // axis(k) &
                            // " is prescribed by &support '" &
                            // trim(config%supports(owner(k, node))%name) &
                            // "' (the force would be ignored)")
                        return
                    end do
                end do
            end associate
        end do
    end subroutine check_loads

    !> A list of node ids of a support or load: not empty, in range, no repeats.
    subroutine check_node_list(error, label, nodes, n_nodes)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: label
        integer, intent(in) :: nodes(:)
        integer, intent(in) :: n_nodes
        integer, allocatable :: position(:)
        integer :: i

        if (size(nodes) == 0) then
            call fatal_error(error, label // ': nodes is empty (give at least one node id)')
            return
        end if
        allocate(position(n_nodes), source=0)
        do i = 1, size(nodes)
            call require_node(error, label, 'nodes', i, nodes(i), n_nodes)
            if (allocated(error)) return
            if (position(nodes(i)) /= 0) then
                call fatal_error(error, label // ': nodes(' // format_integer(position(nodes(i))) &
                    // ') and nodes(' // format_integer(i) // ') are both node ' &
                    // format_integer(nodes(i)))
                return
            end if
            position(nodes(i)) = i
        end do
    end subroutine check_node_list

    subroutine require_node(error, label, variable, i, node, n_nodes)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: label, variable
        integer, intent(in) :: i, node, n_nodes

        if (node < 1 .or. node > n_nodes) then
            call fatal_error(error, label // ': ' // variable // '(' // format_integer(i) &
                // ') = ' // format_integer(node) // ' is not a node (node ids are 1..' &
                // format_integer(n_nodes) // ')')
        end if
    end subroutine require_node

    subroutine check_path(path, error)
        type(path_config_type), intent(in) :: path
        type(error_type), allocatable, intent(out) :: error
        integer :: n, i

        if (.not. allocated(path%time)) then
            call fatal_error(error, '&path: group missing (give the load path, e.g. ' &
                // '&path time = 0, 1, p_disp = 0, 1 /)')
            return
        end if
        n = size(path%time)
        if (n < 2) then
            call fatal_error(error, '&path: time has ' // format_integer(n) &
                // ' knot(s); at least 2 are needed')
            return
        end if
        if (size(path%p_force) /= n) then
            call fatal_error(error, '&path: p_force has ' // format_integer(size(path%p_force)) &
                // ' values but time has ' // format_integer(n))
            return
        end if
        if (size(path%p_disp) /= n) then
            call fatal_error(error, '&path: p_disp has ' // format_integer(size(path%p_disp)) &
                // ' values but time has ' // format_integer(n))
            return
        end if
        do i = 1, n
            if (.not. ieee_is_finite(path%time(i))) then
                call not_finite(error, '&path', 'time(' // format_integer(i) // ')', path%time(i))
            else if (.not. ieee_is_finite(path%p_force(i))) then
                call not_finite(error, '&path', 'p_force(' // format_integer(i) // ')', &
                    path%p_force(i))
            else if (.not. ieee_is_finite(path%p_disp(i))) then
                call not_finite(error, '&path', 'p_disp(' // format_integer(i) // ')', &
                    path%p_disp(i))
            end if
            if (allocated(error)) return
        end do
        do i = 2, n
            if (.not. (path%time(i) > path%time(i - 1))) then
                call fatal_error(error, '&path: time(' // format_integer(i) // ') = ' &
                    // format_real(path%time(i)) // ' is not greater than time(' &
                    // format_integer(i - 1) // ') = ' // format_real(path%time(i - 1)) &
                    // ' (time must be strictly increasing)')
                return
            end if
        end do
    end subroutine check_path

    !> Every continuation step (at least min_step times the shortest knot interval) must
    !> advance the pseudo-time: it must not be below the floating-point resolution of the
    !> path's times.
    subroutine check_step_resolution(solver, path, error)
        type(solver_config_type), intent(in) :: solver
        type(path_config_type), intent(in) :: path
        type(error_type), allocatable, intent(out) :: error
        real(wp) :: largest, interval
        character(len=16) :: shortest

        largest = maxval(abs(path%time))
        interval = minval(path%time(2:) - path%time(:size(path%time) - 1))
        if (solver%min_step * interval < time_resolution * largest) then
            write(shortest, '(es9.2)') time_resolution * largest
            call fatal_error(error, '&solver: min_step = ' // format_real(solver%min_step) &
                // ' is below the resolution of &path time (up to ' // format_real(largest) &
                // ' in magnitude, shortest knot interval ' // format_real(interval) &
                // '): a step shorter than ' // trim(adjustl(shortest)) &
                // ' would not advance the pseudo-time; raise min_step (a fraction of the ' &
                // 'knot interval) or move the path times closer to 0')
        end if
    end subroutine check_step_resolution

    !> A law parameter that must be set, finite and >= 0.
    subroutine require_nonnegative_parameter(error, label, variable, value, unset, law)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: label, variable, law
        real(wp), intent(in) :: value, unset

        if (value == unset) then
            call fatal_error(error, label // ': ' // variable // " is not set (law '" // law &
                // "' needs it)")
        else if (.not. ieee_is_finite(value)) then
            call not_finite(error, label, variable, value)
        else if (value < 0.0_wp) then
            call fatal_error(error, label // ': ' // variable // ' = ' // format_real(value) &
                // ' must be >= 0')
        end if
    end subroutine require_nonnegative_parameter

    !> "; did you mean 'x'?" for the known name closest to `name`, or ''.
    function suggestion(name, names) result(text)
        character(len=*), intent(in) :: name
        character(len=*), intent(in) :: names(:)
        character(len=:), allocatable :: text

        text = closest_name(trim(name), names)
        if (len(text) > 0) text = "; did you mean '" // text // "'?"
    end function suggestion

    subroutine require_positive(error, label, variable, value)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: label, variable
        real(wp), intent(in) :: value

        if (.not. ieee_is_finite(value)) then
            call not_finite(error, label, variable, value)
        else if (value <= 0.0_wp) then
            call fatal_error(error, label // ': ' // variable // ' = ' // format_real(value) &
                // ' must be positive')
        end if
    end subroutine require_positive

    subroutine not_finite(error, label, variable, value)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: label, variable
        real(wp), intent(in) :: value

        call fatal_error(error, label // ': ' // variable // ' = ' // format_real(value) &
            // ' is not finite')
    end subroutine not_finite

    subroutine require_at_least(error, label, variable, value, minimum)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: label, variable
        integer, intent(in) :: value, minimum

        if (value < minimum) then
            call fatal_error(error, label // ': ' // variable // ' = ' // format_integer(value) &
                // ' must be >= ' // format_integer(minimum))
        end if
    end subroutine require_at_least

    !> "'a', 'b', 'c'"
    pure function quoted_list(names) result(list)
        character(len=*), intent(in) :: names(:)
        character(len=:), allocatable :: list
        integer :: i

        list = ''
        do i = 1, size(names)
            if (i > 1) list = list // ', '
            list = list // "'" // trim(names(i)) // "'"
        end do
    end function quoted_list

    function format_position(x) result(text)
        real(wp), intent(in) :: x(3)
        character(len=:), allocatable :: text

        text = format_real(x(1)) // ', ' // format_real(x(2)) // ', ' // format_real(x(3))
    end function format_position

end module yarnfort_input_validate
