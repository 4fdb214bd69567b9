! SPDX-License-Identifier: MIT
!> Unit tests of the XML reader of TexGen files (issue 39 item 6): elements, children in
!> file order, decoded attribute values, and the limits on attributes per tag and on an
!> attribute's length, each an error naming the line, the tag and the limit.
module test_xml_subset
    use yarnfort_testing, only: unittest_type, new_unittest, check
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_text, only: format_integer
    use yarnfort_generate_xml_subset, only: xml_document_type, parse_xml, max_attributes, &
        max_attribute_length
    implicit none
    private

    public :: collect_xml_subset

    character(len=*), parameter :: nl = new_line('a')

contains

    subroutine collect_xml_subset(testsuite)
        type(unittest_type), allocatable, intent(out) :: testsuite(:)

        testsuite = [ &
            new_unittest('children_in_order', test_children_in_order), &
            new_unittest('decoded_values', test_decoded_values), &
            new_unittest('longest_attribute', test_longest_attribute), &
            new_unittest('too_long_attribute', test_too_long_attribute), &
            new_unittest('most_attributes', test_most_attributes), &
            new_unittest('too_many_attributes', test_too_many_attributes), &
            new_unittest('many_elements', test_many_elements), &
            new_unittest('unclosed_long_value', test_unclosed_long_value)]
    end subroutine collect_xml_subset

    !> Children of an element by name, in file order, past comments and other elements.
    subroutine test_children_in_order(error)
        type(error_type), allocatable, intent(out) :: error
        type(xml_document_type) :: document
        integer, allocatable :: found(:)

        call parse_xml('<?xml version="1.0" ?>' // nl // '<Top>' // nl &
            // '  <A i="1"/><B i="x"/><!-- <A i="no"/> --><A i="2">' // nl &
            // '    <A i="inner"/></A>' // nl // '  <B i="y"/><A i="3" />' // nl // '</Top>', &
            document, error)
        if (allocated(error)) return
        found = document%children(0, 'Top')
        call check(error, size(found) == 1, 'one top-level <Top>')
        if (allocated(error)) return
        found = document%children(found(1), 'A')
        call check(error, size(found) == 3, format_integer(size(found)) &
            // ' <A> children instead of 3')
        if (allocated(error)) return
        call expect_value(error, document, found(1), 'i', '1')
        if (allocated(error)) return
        call expect_value(error, document, found(2), 'i', '2')
        if (allocated(error)) return
        call expect_value(error, document, found(3), 'i', '3')
        if (allocated(error)) return
        found = document%children(found(2), 'A')
        call check(error, size(found) == 1, 'one <A> inside the second <A>')
        if (allocated(error)) return
        call expect_value(error, document, found(1), 'i', 'inner')
        if (allocated(error)) return
        found = document%children(0, 'A')
        call check(error, size(found) == 0, 'no top-level <A>')
    end subroutine test_children_in_order

    !> The five entities and character references below 128 decoded; anything else kept.
    subroutine test_decoded_values(error)
        type(error_type), allocatable, intent(out) :: error
        type(xml_document_type) :: document

        call parse_xml('<T a="&lt;&gt;&amp;&quot;&apos;" b=''&#65;&#x42;&#X43;'' ' &
            // 'c="&#200; &unknown; & &amp x &#xZZ;" d="" e="x&longentity;y"/>', &
            document, error)
        if (allocated(error)) return
        call expect_value(error, document, 1, 'a', '<>&"''')
        if (allocated(error)) return
        call expect_value(error, document, 1, 'b', 'ABC')
        if (allocated(error)) return
        call expect_value(error, document, 1, 'c', '&#200; &unknown; & &amp x &#xZZ;')
        if (allocated(error)) return
        call expect_value(error, document, 1, 'd', '')
        if (allocated(error)) return
        call expect_value(error, document, 1, 'e', 'x&longentity;y')
    end subroutine test_decoded_values

    !> A value of exactly the longest length, made of entities and text, decoded.
    subroutine test_longest_attribute(error)
        type(error_type), allocatable, intent(out) :: error
        type(xml_document_type) :: document
        character(len=:), allocatable :: raw, expected

        ! '&amp;x' (6 characters) decodes to '&x'; the rest is padding.
        raw = repeat('&amp;x', max_attribute_length / 6)
        raw = raw // repeat('y', max_attribute_length - len(raw))
        expected = repeat('&x', max_attribute_length / 6) &
            // repeat('y', max_attribute_length - 6 * (max_attribute_length / 6))
        call parse_xml('<T pad="' // raw // '" keep="1"/>', document, error)
        if (allocated(error)) return
        call expect_value(error, document, 1, 'pad', expected)
        if (allocated(error)) return
        call expect_value(error, document, 1, 'keep', '1')
    end subroutine test_longest_attribute

    subroutine test_too_long_attribute(error)
        type(error_type), allocatable, intent(out) :: error
        type(xml_document_type) :: document

        call parse_xml('<T>' // nl // nl // '<U pad="' // repeat('x', max_attribute_length + 1) &
            // '"/></T>', document, error)
        call expect_error(error, 'line 3: tag <U>: the value of attribute pad is longer than ' &
            // format_integer(max_attribute_length) // ' characters (the limit of this reader)')
    end subroutine test_too_long_attribute

    !> The most attributes a tag may have, each with its own value.
    subroutine test_most_attributes(error)
        type(error_type), allocatable, intent(out) :: error
        type(xml_document_type) :: document
        integer :: k

        call parse_xml('<T' // attributes(max_attributes) // '/>', document, error)
        if (allocated(error)) return
        do k = 1, max_attributes, 37
            call expect_value(error, document, 1, 'a' // format_integer(k), &
                'v' // format_integer(k))
            if (allocated(error)) return
        end do
        call expect_value(error, document, 1, 'a' // format_integer(max_attributes), &
            'v' // format_integer(max_attributes))
    end subroutine test_most_attributes

    subroutine test_too_many_attributes(error)
        type(error_type), allocatable, intent(out) :: error
        type(xml_document_type) :: document

        call parse_xml(nl // '<Textile' // attributes(max_attributes + 1) // '>' // nl &
            // '</Textile>', document, error)
        call expect_error(error, 'line 2: tag <Textile> has more than ' &
            // format_integer(max_attributes) // ' attributes (the limit of this reader)')
    end subroutine test_too_many_attributes

    !> 100 000 children of one element, found in order (and in linear time: a list
    !> rebuilt per child would take minutes here).
    subroutine test_many_elements(error)
        type(error_type), allocatable, intent(out) :: error
        integer, parameter :: n = 100000
        type(xml_document_type) :: document
        character(len=:), allocatable :: text
        integer, allocatable :: found(:)
        integer :: k

        text = '<Top>' // repeat('<C/><D/>', n) // '</Top>'
        call parse_xml(text, document, error)
        if (allocated(error)) return
        found = document%children(1, 'D')
        call check(error, size(found) == n, format_integer(size(found)) // ' <D> instead of ' &
            // format_integer(n))
        if (allocated(error)) return
        ! Elements are numbered in file order: <Top> is 1, the k-th <D> is 2k + 1.
        call check(error, all(found == [(2 * k + 1, k = 1, n)]), '<D> not in file order')
    end subroutine test_many_elements

    !> A quote never closed: an error naming the tag, with a shortened attribute name.
    subroutine test_unclosed_long_value(error)
        type(error_type), allocatable, intent(out) :: error
        type(xml_document_type) :: document

        call parse_xml('<T ' // repeat('n', 100) // '="' // repeat('x', 10000), document, &
            error)
        call expect_error(error, 'line 1: tag <T>: the value of attribute ' &
            // repeat('n', 40) // '... is not closed')
    end subroutine test_unclosed_long_value

    !> ' a1="v1" a2="v2" ...' up to n.
    function attributes(n) result(text)
        integer, intent(in) :: n
        character(len=:), allocatable :: text
        character(len=24) :: one
        integer :: k, used

        allocate(character(len=24 * n) :: text)
        used = 0
        do k = 1, n
            write(one, '(" a", i0, "=""v", i0, """")') k, k
            text(used + 1:used + len_trim(one)) = trim(one)
            used = used + len_trim(one)
        end do
        text = text(:used)
    end function attributes

    subroutine expect_value(error, document, element, name, expected)
        type(error_type), allocatable, intent(out) :: error
        type(xml_document_type), intent(in) :: document
        integer, intent(in) :: element
        character(len=*), intent(in) :: name, expected
        character(len=:), allocatable :: value
        logical :: found

        call document%attribute(element, name, value, found)
        if (.not. found) then
            call fatal_error(error, 'attribute ' // name // ' not found')
        else if (value /= expected .or. len(value) /= len(expected)) then
            call fatal_error(error, 'attribute ' // name // ' = "' // value(:min(len(value), &
                60)) // '" (length ' // format_integer(len(value)) // '), expected "' &
                // expected(:min(len(expected), 60)) // '" (length ' &
                // format_integer(len(expected)) // ')')
        end if
    end subroutine expect_value

    !> `error` (from the parse) must hold exactly `expected`; it is replaced by the
    !> test's own verdict.
    subroutine expect_error(error, expected)
        type(error_type), allocatable, intent(inout) :: error
        character(len=*), intent(in) :: expected
        character(len=:), allocatable :: got

        if (.not. allocated(error)) then
            call fatal_error(error, 'no error; expected: ' // expected)
            return
        end if
        got = error%message
        deallocate(error)
        if (got /= expected) call fatal_error(error, 'error "' // got // '" instead of "' &
            // expected // '"')
    end subroutine expect_error

end module test_xml_subset
