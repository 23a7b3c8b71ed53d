!> The only door out of the Fortran kernels: bind(C) procedures that convert arguments
!> (0-based C node numbers, −1 = ground → 1-based, 0 = ground) and call the kernels.
!> Nothing is computed here. Declared for C in c/martello.h.
module martello_api
   use, intrinsic :: iso_c_binding
   use martello_kinds, only: dp
   use martello_status
   use martello_model
   use martello_statics, only: static_result_t, static_solve
   use martello_time_functions
   use martello_contact_laws
   use martello_links
   implicit none
   private
   public :: c_model_create, c_model_free

contains

   !> Handle → model pointer; a null handle is an argument error.
   function get_model(handle) result(mp)
      type(c_ptr), value :: handle
      type(model_t), pointer :: mp
      mp => null()
      if (c_associated(handle)) call c_f_pointer(handle, mp)
   end function get_model

   integer(c_int) function c_model_create(n_nodes, max_links, max_contacts, max_forces, &
                                          max_couplings, handle) bind(C, name='martello_model_create')
      integer(c_int), value :: n_nodes, max_links, max_contacts, max_forces, max_couplings
      type(c_ptr), intent(out) :: handle
      type(model_t), pointer :: mp
      integer :: stat
      handle = c_null_ptr
      allocate (mp, stat=stat)
      if (stat /= 0) then
         c_model_create = MARTELLO_ERR_MEMORY; return
      end if
      call model_init(mp, int(n_nodes), int(max_links), int(max_contacts), int(max_forces), &
                      int(max_couplings), stat)
      if (stat /= MARTELLO_OK) then
         deallocate (mp); c_model_create = stat; return
      end if
      handle = c_loc(mp)
      c_model_create = MARTELLO_OK
   end function c_model_create

   subroutine c_model_free(handle) bind(C, name='martello_model_free')
      type(c_ptr), intent(inout) :: handle
      type(model_t), pointer :: mp
      mp => get_model(handle)
      if (associated(mp)) deallocate (mp)
      handle = c_null_ptr
   end subroutine c_model_free

   integer(c_int) function c_model_set_node(handle, node, mass, u0, v0, fixed) &
      bind(C, name='martello_model_set_node')
      type(c_ptr), value :: handle
      integer(c_int), value :: node, fixed
      real(c_double), value :: mass, u0, v0
      type(model_t), pointer :: mp
      integer :: stat
      mp => get_model(handle)
      if (.not. associated(mp)) then
         c_model_set_node = MARTELLO_ERR_ARGUMENT; return
      end if
      call model_set_node(mp, int(node) + 1, mass, u0, v0, fixed /= 0, stat)
      c_model_set_node = stat
   end function c_model_set_node

   integer(c_int) function c_model_add_link(handle, kind, a, b, par) bind(C, name='martello_model_add_link')
      type(c_ptr), value :: handle
      integer(c_int), value :: kind, a, b
      real(c_double), intent(in) :: par(NPAR_LINK)
      type(model_t), pointer :: mp
      integer :: stat
      mp => get_model(handle)
      if (.not. associated(mp)) then
         c_model_add_link = MARTELLO_ERR_ARGUMENT; return
      end if
      call model_add_link(mp, int(kind), int(a) + 1, int(b) + 1, par, stat)
      c_model_add_link = stat
   end function c_model_add_link

   integer(c_int) function c_model_add_contact(handle, a, b, gap, scheme, law, par) &
      bind(C, name='martello_model_add_contact')
      type(c_ptr), value :: handle
      integer(c_int), value :: a, b, scheme, law
      real(c_double), value :: gap
      real(c_double), intent(in) :: par(NPAR_CONTACT)
      type(model_t), pointer :: mp
      integer :: stat
      mp => get_model(handle)
      if (.not. associated(mp)) then
         c_model_add_contact = MARTELLO_ERR_ARGUMENT; return
      end if
      call model_add_contact(mp, int(a) + 1, int(b) + 1, gap, int(scheme), int(law), par, stat)
      c_model_add_contact = stat
   end function c_model_add_contact

   integer(c_int) function c_model_add_mass_coupling(handle, a, b, value) &
      bind(C, name='martello_model_add_mass_coupling')
      type(c_ptr), value :: handle
      integer(c_int), value :: a, b
      real(c_double), value :: value
      type(model_t), pointer :: mp
      integer :: stat
      mp => get_model(handle)
      if (.not. associated(mp)) then
         c_model_add_mass_coupling = MARTELLO_ERR_ARGUMENT; return
      end if
      call model_add_mass_coupling(mp, int(a) + 1, int(b) + 1, value, stat)
      c_model_add_mass_coupling = stat
   end function c_model_add_mass_coupling

   integer(c_int) function c_model_set_gravity(handle, g) bind(C, name='martello_model_set_gravity')
      type(c_ptr), value :: handle
      real(c_double), value :: g
      type(model_t), pointer :: mp
      mp => get_model(handle)
      c_model_set_gravity = MARTELLO_ERR_ARGUMENT
      if (.not. associated(mp)) return
      if (g /= g .or. abs(g) > huge(g)) then
         mp%errmsg = 'set_gravity: g must be finite'; return
      end if
      mp%gravity = g
      c_model_set_gravity = MARTELLO_OK
   end function c_model_set_gravity

   integer(c_int) function c_model_add_nodal_force(handle, node, kind, par, ntab, t, y) &
      bind(C, name='martello_model_add_nodal_force')
      type(c_ptr), value :: handle
      integer(c_int), value :: node, kind, ntab
      real(c_double), intent(in) :: par(NPAR_TF), t(*), y(*)
      type(model_t), pointer :: mp
      integer :: stat
      mp => get_model(handle)
      if (.not. associated(mp) .or. ntab < 0) then
         c_model_add_nodal_force = MARTELLO_ERR_ARGUMENT; return
      end if
      call model_add_nodal_force(mp, int(node) + 1, int(kind), par, t(1:ntab), y(1:ntab), stat)
      c_model_add_nodal_force = stat
   end function c_model_add_nodal_force

   integer(c_int) function c_model_set_ground_acceleration(handle, kind, par, ntab, t, y) &
      bind(C, name='martello_model_set_ground_acceleration')
      type(c_ptr), value :: handle
      integer(c_int), value :: kind, ntab
      real(c_double), intent(in) :: par(NPAR_TF), t(*), y(*)
      type(model_t), pointer :: mp
      integer :: stat
      mp => get_model(handle)
      if (.not. associated(mp) .or. ntab < 0) then
         c_model_set_ground_acceleration = MARTELLO_ERR_ARGUMENT; return
      end if
      call model_set_ground_acceleration(mp, int(kind), par, t(1:ntab), y(1:ntab), stat)
      c_model_set_ground_acceleration = stat
   end function c_model_set_ground_acceleration

   !> Copy the model's last error or warning message into buf (NUL-terminated, truncated).
   integer(c_int) function c_model_message(handle, buf, buflen) bind(C, name='martello_model_message')
      type(c_ptr), value :: handle
      integer(c_int), value :: buflen
      character(kind=c_char), intent(out) :: buf(*)
      type(model_t), pointer :: mp
      integer :: i, n
      mp => get_model(handle)
      c_model_message = MARTELLO_ERR_ARGUMENT
      if (.not. associated(mp) .or. buflen < 1) return
      n = min(len_trim(mp%errmsg), int(buflen) - 1)
      do i = 1, n
         buf(i) = mp%errmsg(i:i)
      end do
      buf(n + 1) = c_null_char
      c_model_message = MARTELLO_OK
   end function c_model_message

   integer(c_int) function c_static_solve(handle, tol, max_iter, u, force, penetration, active, &
                                          counters, conditioning) bind(C, name='martello_static_solve')
      type(c_ptr), value :: handle
      real(c_double), value :: tol
      integer(c_int), value :: max_iter
      real(c_double), intent(out) :: u(*), force(*), penetration(*), conditioning(4)
      integer(c_int), intent(out) :: active(*), counters(3)
      type(model_t), pointer :: mp
      type(static_result_t) :: r
      integer :: stat, n, nc
      mp => get_model(handle)
      c_static_solve = MARTELLO_ERR_ARGUMENT
      if (.not. associated(mp)) return
      if (.not. (tol > 0.0_dp) .or. max_iter < 1) then
         mp%errmsg = 'static_solve: need tol > 0 and max_iter >= 1'; return
      end if
      if (any(mp%mass(1:mp%n) < 0.0_dp)) then
         mp%errmsg = 'static_solve: every node must be set (set_node) before solving'
         c_static_solve = MARTELLO_ERR_STATE; return
      end if
      mp%errmsg = ''
      call static_solve(mp, tol, int(max_iter), r, stat)
      n = mp%n; nc = mp%ncontact
      if (allocated(r%u)) then
         u(1:n) = r%u; force(1:nc) = r%force; penetration(1:nc) = r%penetration
         active(1:nc) = merge(1, 0, r%active)
      end if
      counters = [r%active_set_iterations, r%uzawa_iterations, r%solves]
      conditioning = [r%rcond, r%digits_lost, r%penalty_ratio, r%penalised_rcond]
      c_static_solve = stat
   end function c_static_solve

   !> Named integer constants of the kernels (laws, links, schemes, parameter slots, status
   !> codes): one source of truth for C and Python. Returns MARTELLO_ERR_ARGUMENT if unknown.
   integer(c_int) function c_constant(cname, value) bind(C, name='martello_constant')
      character(kind=c_char), intent(in) :: cname(*)
      integer(c_int), intent(out) :: value
      character(len=64) :: name
      integer :: i, v
      name = ''
      do i = 1, 64
         if (cname(i) == c_null_char) exit
         name(i:i) = cname(i)
      end do
      c_constant = MARTELLO_OK
      select case (trim(name))
      case ('LAW_LINEAR'); v = LAW_LINEAR
      case ('LAW_HERTZ'); v = LAW_HERTZ
      case ('LAW_KELVIN'); v = LAW_KELVIN
      case ('LAW_HUNT_CROSSLEY'); v = LAW_HUNT_CROSSLEY
      case ('LAW_LANKARANI_NIKRAVESH'); v = LAW_LANKARANI_NIKRAVESH
      case ('LAW_FLORES'); v = LAW_FLORES
      case ('LAW_GONTHIER'); v = LAW_GONTHIER
      case ('LAW_HERTZDAMP'); v = LAW_HERTZDAMP
      case ('LAW_JANKOWSKI'); v = LAW_JANKOWSKI
      case ('NPAR_CONTACT'); v = NPAR_CONTACT
      case ('P_STIFF'); v = P_STIFF - 1
      case ('P_EXPONENT'); v = P_EXPONENT - 1
      case ('P_DAMPING'); v = P_DAMPING - 1
      case ('P_RESTITUTION'); v = P_RESTITUTION - 1
      case ('P_CLIP'); v = P_CLIP - 1
      case ('P_MSTAR'); v = P_MSTAR - 1
      case ('LINK_SPRING'); v = LINK_SPRING
      case ('LINK_DASHPOT'); v = LINK_DASHPOT
      case ('LINK_BILINEAR'); v = LINK_BILINEAR
      case ('LINK_FLUID_DAMPER'); v = LINK_FLUID_DAMPER
      case ('LINK_BAR'); v = LINK_BAR
      case ('NPAR_LINK'); v = NPAR_LINK
      case ('L_STIFF'); v = L_STIFF - 1
      case ('L_DAMP'); v = L_DAMP - 1
      case ('L_YIELD'); v = L_YIELD - 1
      case ('L_HARDENING'); v = L_HARDENING - 1
      case ('L_ALPHA'); v = L_ALPHA - 1
      case ('L_VREG'); v = L_VREG - 1
      case ('SCHEME_PENALTY'); v = SCHEME_PENALTY
      case ('SCHEME_LAGRANGE'); v = SCHEME_LAGRANGE
      case ('SCHEME_AUGMENTED'); v = SCHEME_AUGMENTED
      case ('SCHEME_RESTITUTION'); v = SCHEME_RESTITUTION
      case ('TF_CONSTANT'); v = TF_CONSTANT
      case ('TF_TABLE'); v = TF_TABLE
      case ('TF_SINE'); v = TF_SINE
      case ('TF_RECTANGULAR'); v = TF_RECTANGULAR
      case ('TF_HALF_SINE'); v = TF_HALF_SINE
      case ('NPAR_TF'); v = NPAR_TF
      case ('MARTELLO_OK'); v = MARTELLO_OK
      case ('MARTELLO_ILL_CONDITIONED'); v = MARTELLO_ILL_CONDITIONED
      case ('MARTELLO_ROOT_FOUND'); v = MARTELLO_ROOT_FOUND
      case ('MARTELLO_ERR_ARGUMENT'); v = MARTELLO_ERR_ARGUMENT
      case ('MARTELLO_ERR_MEMORY'); v = MARTELLO_ERR_MEMORY
      case ('MARTELLO_ERR_SINGULAR'); v = MARTELLO_ERR_SINGULAR
      case ('MARTELLO_ERR_NOT_CONVERGED'); v = MARTELLO_ERR_NOT_CONVERGED
      case ('MARTELLO_ERR_DIVERGED'); v = MARTELLO_ERR_DIVERGED
      case ('MARTELLO_ERR_UNSUPPORTED'); v = MARTELLO_ERR_UNSUPPORTED
      case ('MARTELLO_ERR_UNSTABLE'); v = MARTELLO_ERR_UNSTABLE
      case ('MARTELLO_ERR_LAPACK'); v = MARTELLO_ERR_LAPACK
      case ('MARTELLO_ERR_STEP_UNDERFLOW'); v = MARTELLO_ERR_STEP_UNDERFLOW
      case ('MARTELLO_ERR_EXTERNAL'); v = MARTELLO_ERR_EXTERNAL
      case ('MARTELLO_ERR_STATE'); v = MARTELLO_ERR_STATE
      case default
         v = 0; c_constant = MARTELLO_ERR_ARGUMENT
      end select
      value = v
   end function c_constant
end module martello_api
