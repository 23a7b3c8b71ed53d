!> The door of the closed forms (martello_closed_form of c/martello.h, docs/c-api.md "Closed
!> forms"): converts the C arguments and calls martello_closed_forms, as every api_* door
!> only converts.
module martello_api_closed_forms
   use, intrinsic :: iso_c_binding, only: c_int, c_double, c_char
   use martello_kinds, only: dp
   use martello_status, only: MARTELLO_ERR_ARGUMENT
   use martello_closed_forms, only: closed_form
   use martello_api_handles, only: from_c_string
   implicit none
   private

contains

   !> C door: name (NUL-terminated), n_par parameters; out must hold 4 values; *n_out the
   !> number written.
   integer(c_int) function c_closed_form(name, par, n_par, out, n_out) &
      bind(C, name='martello_closed_form')
      character(kind=c_char), intent(in) :: name(*)
      integer(c_int), value :: n_par
      real(c_double), intent(in) :: par(*)
      real(c_double), intent(out) :: out(4)
      integer(c_int), intent(out) :: n_out
      integer :: stat, n
      real(dp) :: o(4)
      c_closed_form = MARTELLO_ERR_ARGUMENT; n_out = 0; out = 0.0_dp
      if (n_par < 0 .or. n_par > 16) return
      call closed_form(from_c_string(name, 32), par(1:n_par), o, n, stat)
      out = o; n_out = n
      c_closed_form = stat
   end function c_closed_form
end module martello_api_closed_forms
