! SPDX-License-Identifier: MIT
!> Force and friction laws by name for the Python facade: build a law as a scene does
!> (the scene builder's constructors) and evaluate it on arrays. Kept out of `yarnfort_facade`, which f2py reads,
!> because f2py cannot parse polymorphic code.
module yarnfort_facade_laws
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_material_force_law, only: force_law_type
    use yarnfort_friction_law, only: friction_law_type
    use yarnfort_input_config, only: material_config_type, contact_config_type
    use yarnfort_scene_builder, only: new_force_law, new_friction_law
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
        type(material_config_type) :: material
        integer :: i

        allocate(force(size(stretch)), dforce(size(stretch)), energy(size(stretch)), &
            source=0.0_wp)
        material%law = law
        material%stiffness = p1
        material%modulus = p1
        material%area = p2
        material%table_file = table_file
        call new_force_law(force_law, material, error)
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
        type(contact_config_type) :: contact
        integer :: i, n

        n = size(tension_min)
        allocate(critical(n), dcritical_dtension(n), dcritical_dangle(n), source=0.0_wp)
        if (size(angle) /= n) then
            call fatal_error(error, 'friction law: tension_min and angle differ in size')
            return
        end if
        contact%law = law
        contact%friction_coefficient = mu
        contact%adhesion = beta
        contact%decay_start = w_d
        contact%decay_end = s_d
        contact%rate_table = rate_table
        call new_friction_law(friction_law, contact, error, '')
        if (allocated(error)) return
        if (.not. allocated(friction_law)) then
            call fatal_error(error, "friction law '" // trim(law) // "' has no critical " &
                // 'tension (a bonded contact never slides)')
            return
        end if
        do i = 1, n
            call friction_law%get_critical_tension(tension_min(i), angle(i), critical(i), &
                dcritical_dtension(i), dcritical_dangle(i))
        end do
    end subroutine get_critical_tensions

end module yarnfort_facade_laws
