! SPDX-License-Identifier: MIT
!> Force and friction laws by name for the Python facade: build a law with the library's
!> constructors and evaluate it on arrays. Kept out of `yarnfort_facade`, which f2py reads,
!> because f2py cannot parse polymorphic code.
module yarnfort_facade_laws
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_material_law, only: force_law_type
    use yarnfort_material_linear, only: linear_law_type, new_linear_law
    use yarnfort_material_neo_hookean, only: neo_hookean_law_type, new_neo_hookean_law
    use yarnfort_material_table, only: table_law_type, read_table_law
    use yarnfort_friction_law, only: friction_law_type
    use yarnfort_friction_coulomb, only: coulomb_law_type, new_coulomb_law
    use yarnfort_friction_adhesion, only: adhesion_law_type, new_adhesion_law
    use yarnfort_friction_decaying_adhesion, only: decaying_adhesion_law_type, &
        new_decaying_adhesion_law
    use yarnfort_friction_general, only: rate_table_law_type => table_law_type, &
        read_rate_table
    implicit none
    private

    public :: get_force_law_values, get_critical_tensions

contains

    !> Tension, its derivative and the energy per unit reference length of the force law
    !> `law` ('linear': p1 = EA; 'neo_hookean': p1 = C, p2 = S1; 'table': `table_file`)
    !> at each stretch.
    subroutine get_force_law_values(law, p1, p2, table_file, stretch, force, dforce, &
            energy, error)
        character(len=*), intent(in) :: law
        real(wp), intent(in) :: p1, p2
        character(len=*), intent(in) :: table_file
        real(wp), intent(in) :: stretch(:)
        real(wp), allocatable, intent(out) :: force(:), dforce(:), energy(:)
        type(error_type), allocatable, intent(out) :: error
        class(force_law_type), allocatable :: force_law
        integer :: i

        allocate(force(size(stretch)), dforce(size(stretch)), energy(size(stretch)), &
            source=0.0_wp)
        call new_force_law(force_law, law, p1, p2, table_file, error)
        if (allocated(error)) return
        do i = 1, size(stretch)
            call force_law%get_force(stretch(i), force(i), dforce(i))
            energy(i) = force_law%get_energy(stretch(i))
        end do
    end subroutine get_force_law_values

    !> Critical tension of the friction law `law` ('coulomb': mu; 'adhesion': mu, beta;
    !> 'decaying_adhesion': mu, beta, w_d, s_d; 'general': the CSV `rate_table` of T, g)
    !> and its derivatives with respect to T_min and alpha, at each pair (tension_min(i),
    !> angle(i)).
    subroutine get_critical_tensions(law, mu, beta, w_d, s_d, rate_table, tension_min, angle, &
            critical, dcritical_dtension, dcritical_dangle, error)
        character(len=*), intent(in) :: law, rate_table
        real(wp), intent(in) :: mu, beta, w_d, s_d
        real(wp), intent(in) :: tension_min(:), angle(:)
        real(wp), allocatable, intent(out) :: critical(:), dcritical_dtension(:), &
            dcritical_dangle(:)
        type(error_type), allocatable, intent(out) :: error
        class(friction_law_type), allocatable :: friction_law
        integer :: i, n

        n = size(tension_min)
        allocate(critical(n), dcritical_dtension(n), dcritical_dangle(n), source=0.0_wp)
        if (size(angle) /= n) then
            call fatal_error(error, 'friction law: tension_min and angle differ in size')
            return
        end if
        call new_friction_law(friction_law, law, mu, beta, w_d, s_d, rate_table, error)
        if (allocated(error)) return
        do i = 1, n
            call friction_law%get_critical_tension(tension_min(i), angle(i), critical(i), &
                dcritical_dtension(i), dcritical_dangle(i))
        end do
    end subroutine get_critical_tensions

    !> Build the force law named `law` with the library's constructors.
    subroutine new_force_law(force_law, law, p1, p2, table_file, error)
        class(force_law_type), allocatable, intent(out) :: force_law
        character(len=*), intent(in) :: law
        real(wp), intent(in) :: p1, p2
        character(len=*), intent(in) :: table_file
        type(error_type), allocatable, intent(out) :: error

        select case (trim(law))
        case ('linear')
            block
                type(linear_law_type), allocatable :: linear
                allocate(linear)
                call new_linear_law(linear, p1, error)
                call move_alloc(linear, force_law)
            end block
        case ('neo_hookean')
            block
                type(neo_hookean_law_type), allocatable :: neo_hookean
                allocate(neo_hookean)
                call new_neo_hookean_law(neo_hookean, p1, p2, error)
                call move_alloc(neo_hookean, force_law)
            end block
        case ('table')
            block
                type(table_law_type), allocatable :: table
                allocate(table)
                call read_table_law(table, trim(table_file), error)
                call move_alloc(table, force_law)
            end block
        case default
            call fatal_error(error, "force law '" // trim(law) &
                // "' is unknown (use linear, neo_hookean or table)")
        end select
    end subroutine new_force_law

    !> Build the friction law named `law` with the library's constructors.
    subroutine new_friction_law(friction_law, law, mu, beta, w_d, s_d, rate_table, error)
        class(friction_law_type), allocatable, intent(out) :: friction_law
        character(len=*), intent(in) :: law, rate_table
        real(wp), intent(in) :: mu, beta, w_d, s_d
        type(error_type), allocatable, intent(out) :: error

        select case (trim(law))
        case ('coulomb')
            block
                type(coulomb_law_type), allocatable :: coulomb
                allocate(coulomb)
                call new_coulomb_law(coulomb, mu, error)
                call move_alloc(coulomb, friction_law)
            end block
        case ('adhesion')
            block
                type(adhesion_law_type), allocatable :: adhesion
                allocate(adhesion)
                call new_adhesion_law(adhesion, mu, beta, error)
                call move_alloc(adhesion, friction_law)
            end block
        case ('decaying_adhesion')
            block
                type(decaying_adhesion_law_type), allocatable :: decaying
                allocate(decaying)
                call new_decaying_adhesion_law(decaying, mu, beta, w_d, s_d, error)
                call move_alloc(decaying, friction_law)
            end block
        case ('general')
            block
                type(rate_table_law_type), allocatable :: general
                allocate(general)
                call read_rate_table(general, trim(rate_table), error)
                call move_alloc(general, friction_law)
            end block
        case default
            call fatal_error(error, "friction law '" // trim(law) &
                // "' is unknown (use coulomb, adhesion, decaying_adhesion or general)")
        end select
    end subroutine new_friction_law

end module yarnfort_facade_laws
