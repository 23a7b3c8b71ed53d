!> The C door of the registry (martello_registry_* of c/martello.h): converts names and
!> indices (0-based in C) and calls martello_registry. Nothing is defined here.
module martello_api_registry
   use, intrinsic :: iso_c_binding
   use martello_kinds, only: dp
   use martello_status
   use martello_registry, only: registry_shape, registry_column, registry_row, registry_find, &
      NAME_LEN, TEXT_LEN, MAX_COLS
   use martello_api_handles, only: from_c_string
   implicit none
   private

contains

   integer(c_int) function c_registry_shape(table, rows, cols) bind(C, name='martello_registry_shape')
      character(kind=c_char), intent(in) :: table(*)
      integer(c_int), intent(out) :: rows, cols
      logical :: ok
      integer :: r, c
      call registry_shape(from_c_string(table, NAME_LEN), r, c, ok)
      rows = r; cols = c
      c_registry_shape = merge(MARTELLO_OK, MARTELLO_ERR_ARGUMENT, ok)
   end function c_registry_shape

   integer(c_int) function c_registry_column(table, j, name, namelen) &
      bind(C, name='martello_registry_column')
      character(kind=c_char), intent(in) :: table(*)
      integer(c_int), value :: j, namelen
      type(c_ptr), value :: name
      character(len=NAME_LEN) :: col
      logical :: ok
      call registry_column(from_c_string(table, NAME_LEN), int(j) + 1, col, ok)
      c_registry_column = MARTELLO_ERR_ARGUMENT
      if (ok) c_registry_column = put_string(col, name, namelen)
   end function c_registry_column

   !> Row i: its name (if name is not NULL) and its cols numbers (if values is not NULL).
   integer(c_int) function c_registry_entry(table, i, name, namelen, values) &
      bind(C, name='martello_registry_entry')
      character(kind=c_char), intent(in) :: table(*)
      integer(c_int), value :: i, namelen
      type(c_ptr), value :: name, values
      character(len=NAME_LEN) :: rname
      character(len=TEXT_LEN) :: text
      real(dp) :: v(MAX_COLS)
      real(c_double), pointer :: pv(:)
      integer :: rows, cols
      logical :: ok
      call registry_shape(from_c_string(table, NAME_LEN), rows, cols, ok)
      call registry_row(from_c_string(table, NAME_LEN), int(i) + 1, rname, v, text, ok)
      c_registry_entry = MARTELLO_ERR_ARGUMENT
      if (.not. ok) return
      if (c_associated(values)) then
         call c_f_pointer(values, pv, [cols]); pv = v(1:cols)
      end if
      c_registry_entry = put_string(rname, name, namelen)
   end function c_registry_entry

   !> What row i is (or, in the table "tables", the prefix of its C constants).
   integer(c_int) function c_registry_text(table, i, text, textlen) bind(C, name='martello_registry_text')
      character(kind=c_char), intent(in) :: table(*)
      integer(c_int), value :: i, textlen
      type(c_ptr), value :: text
      character(len=NAME_LEN) :: rname
      character(len=TEXT_LEN) :: rtext
      real(dp) :: v(MAX_COLS)
      logical :: ok
      call registry_row(from_c_string(table, NAME_LEN), int(i) + 1, rname, v, rtext, ok)
      c_registry_text = MARTELLO_ERR_ARGUMENT
      if (ok) c_registry_text = put_string(rtext, text, textlen)
   end function c_registry_text

   !> The row (0-based) named name; MARTELLO_ERR_ARGUMENT (i = -1) if there is none.
   integer(c_int) function c_registry_find(table, name, i) bind(C, name='martello_registry_find')
      character(kind=c_char), intent(in) :: table(*), name(*)
      integer(c_int), intent(out) :: i
      i = registry_find(from_c_string(table, NAME_LEN), from_c_string(name, NAME_LEN)) - 1
      c_registry_find = merge(MARTELLO_OK, MARTELLO_ERR_ARGUMENT, i >= 0)
   end function c_registry_find

   !> Copy text (trimmed) into the C buffer buf of buflen bytes, NUL-terminated; a NULL buf
   !> takes nothing. MARTELLO_ERR_ARGUMENT if it does not fit (registry names are never cut).
   integer(c_int) function put_string(text, buf, buflen) result(stat)
      character(len=*), intent(in) :: text
      type(c_ptr), value :: buf
      integer(c_int), value :: buflen
      character(kind=c_char), pointer :: pb(:)
      integer :: k, n
      stat = MARTELLO_OK
      if (.not. c_associated(buf)) return
      n = len_trim(text)
      stat = MARTELLO_ERR_ARGUMENT
      if (buflen < n + 1) return
      call c_f_pointer(buf, pb, [n + 1])
      do k = 1, n
         pb(k) = text(k:k)
      end do
      pb(n + 1) = c_null_char
      stat = MARTELLO_OK
   end function put_string
end module martello_api_registry
