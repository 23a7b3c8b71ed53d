!> The C door of the model handle (martello_model_* and martello_static_solve of
!> c/martello.h): converts arguments (0-based C nodes, −1 = ground → 1-based, 0 = ground)
!> and calls martello_model / martello_statics. Nothing is computed here.
module martello_api_model
   use, intrinsic :: iso_c_binding
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use martello_kinds, only: dp
   use martello_status
   use martello_model
   use martello_time_functions, only: NPAR_TF
   use martello_contact_laws, only: NPAR_CONTACT
   use martello_links, only: NPAR_LINK
   use martello_statics, only: static_result_t, static_solve
   use martello_effective_mass, only: contact_effective_masses
   use martello_api_handles, only: get_model, copy_message
   implicit none
   private

contains

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

   !> A link or contact as a row of n terms, nodes 0-based (−1: the ground), its deformation
   !> Σ coef·u(node) (docs/buildings.md, "Contacts between plan points").
   integer(c_int) function c_model_add_link_row(handle, kind, n, nodes, coef, par) &
      bind(C, name='martello_model_add_link_row')
      type(c_ptr), value :: handle
      integer(c_int), value :: kind, n
      integer(c_int), intent(in) :: nodes(*)
      real(c_double), intent(in) :: coef(*), par(NPAR_LINK)
      type(model_t), pointer :: mp
      integer :: stat
      mp => get_model(handle)
      c_model_add_link_row = MARTELLO_ERR_ARGUMENT
      if (.not. associated(mp)) return
      if (n < 0) then
         mp%errmsg = 'add_link_row: n must be >= 0'; return
      end if
      call model_add_link_row(mp, int(kind), int(nodes(1:n)) + 1, coef(1:n), par, stat)
      c_model_add_link_row = stat
   end function c_model_add_link_row

   integer(c_int) function c_model_add_contact_row(handle, n, nodes, coef, gap, scheme, law, par) &
      bind(C, name='martello_model_add_contact_row')
      type(c_ptr), value :: handle
      integer(c_int), value :: n, scheme, law
      integer(c_int), intent(in) :: nodes(*)
      real(c_double), intent(in) :: coef(*)
      real(c_double), value :: gap
      real(c_double), intent(in) :: par(NPAR_CONTACT)
      type(model_t), pointer :: mp
      integer :: stat
      mp => get_model(handle)
      c_model_add_contact_row = MARTELLO_ERR_ARGUMENT
      if (.not. associated(mp)) return
      if (n < 0) then
         mp%errmsg = 'add_contact_row: n must be >= 0'; return
      end if
      call model_add_contact_row(mp, int(nodes(1:n)) + 1, coef(1:n), gap, int(scheme), int(law), &
                                 par, stat)
      c_model_add_contact_row = stat
   end function c_model_add_contact_row

   !> The bulk doors: n entries in one call, each checked exactly as by the one-entry door it
   !> repeats (same model, same order); the first bad entry stops the call, and the message
   !> names its 0-based index (docs/c-api.md, "Building a large model").
   integer(c_int) function c_model_set_nodes(handle, n, mass, u0, v0, fixed) &
      bind(C, name='martello_model_set_nodes')
      type(c_ptr), value :: handle
      integer(c_int), value :: n
      real(c_double), intent(in) :: mass(*), u0(*), v0(*)
      integer(c_int), intent(in) :: fixed(*)
      type(model_t), pointer :: mp
      integer :: i, stat
      mp => get_model(handle)
      if (.not. associated(mp) .or. n < 0) then
         c_model_set_nodes = MARTELLO_ERR_ARGUMENT; return
      end if
      stat = MARTELLO_OK
      do i = 1, n
         call model_set_node(mp, i, mass(i), u0(i), v0(i), fixed(i) /= 0, stat)
         if (stat /= MARTELLO_OK) exit
      end do
      if (stat /= MARTELLO_OK) call name_entry(mp, i)
      c_model_set_nodes = stat
   end function c_model_set_nodes

   !> par is n rows of MARTELLO_NPAR_LINK (row-major in C: par[i*NPAR_LINK + j]).
   integer(c_int) function c_model_add_links(handle, n, kind, a, b, par) &
      bind(C, name='martello_model_add_links')
      type(c_ptr), value :: handle
      integer(c_int), value :: n
      integer(c_int), intent(in) :: kind(*), a(*), b(*)
      real(c_double), intent(in) :: par(NPAR_LINK, *)
      type(model_t), pointer :: mp
      integer :: i, stat
      mp => get_model(handle)
      if (.not. associated(mp) .or. n < 0) then
         c_model_add_links = MARTELLO_ERR_ARGUMENT; return
      end if
      stat = MARTELLO_OK
      do i = 1, n
         call model_add_link(mp, int(kind(i)), int(a(i)) + 1, int(b(i)) + 1, par(:, i), stat)
         if (stat /= MARTELLO_OK) exit
      end do
      if (stat /= MARTELLO_OK) call name_entry(mp, i)
      c_model_add_links = stat
   end function c_model_add_links

   !> par is n rows of MARTELLO_NPAR_CONTACT (row-major in C).
   integer(c_int) function c_model_add_contacts(handle, n, a, b, gap, scheme, law, par) &
      bind(C, name='martello_model_add_contacts')
      type(c_ptr), value :: handle
      integer(c_int), value :: n
      integer(c_int), intent(in) :: a(*), b(*), scheme(*), law(*)
      real(c_double), intent(in) :: gap(*), par(NPAR_CONTACT, *)
      type(model_t), pointer :: mp
      integer :: i, stat
      mp => get_model(handle)
      if (.not. associated(mp) .or. n < 0) then
         c_model_add_contacts = MARTELLO_ERR_ARGUMENT; return
      end if
      stat = MARTELLO_OK
      do i = 1, n
         call model_add_contact(mp, int(a(i)) + 1, int(b(i)) + 1, gap(i), int(scheme(i)), &
                                int(law(i)), par(:, i), stat)
         if (stat /= MARTELLO_OK) exit
      end do
      if (stat /= MARTELLO_OK) call name_entry(mp, i)
      c_model_add_contacts = stat
   end function c_model_add_contacts

   !> A chain held per node (docs/c-api.md "Chains"): first 0-based; k required; c, fy,
   !> hardening, gap and par may be NULL (no dashpots, linear springs, no contacts).
   integer(c_int) function c_model_add_chain(handle, first, n, k, c, fy, hardening, gap, scheme, &
                                             law, par) bind(C, name='martello_model_add_chain')
      type(c_ptr), value :: handle, k, c, fy, hardening, gap, par
      integer(c_int), value :: first, n, scheme, law
      type(model_t), pointer :: mp
      real(c_double), pointer :: pk(:), pc(:), pf(:), ph(:), pg(:), pp(:)
      real(dp) :: row(NPAR_CONTACT)
      integer :: stat
      mp => get_model(handle)
      c_model_add_chain = MARTELLO_ERR_ARGUMENT
      if (.not. associated(mp)) return
      if (n < 1 .or. .not. c_associated(k) .or. (c_associated(gap) .and. .not. c_associated(par))) then
         mp%errmsg = 'add_chain: need n >= 1, the springs k, and par with the gaps'; return
      end if
      call c_f_pointer(k, pk, [n])
      row = 0.0_dp
      if (c_associated(par)) then
         call c_f_pointer(par, pp, [NPAR_CONTACT]); row = pp
      end if
      pc => null(); pf => null(); ph => null(); pg => null()
      if (c_associated(c)) call c_f_pointer(c, pc, [n])
      if (c_associated(fy)) call c_f_pointer(fy, pf, [n])
      if (c_associated(hardening)) call c_f_pointer(hardening, ph, [n])
      if (c_associated(gap)) call c_f_pointer(gap, pg, [max(n - 1, 1)])
      ! a disassociated pointer is an absent optional argument
      call model_add_chain(mp, int(first) + 1, int(n), pk, pc, pf, ph, pg, int(scheme), &
                           int(law), row, stat)
      c_model_add_chain = stat
   end function c_model_add_chain

   !> Prefix the model's message with the failing bulk entry's 0-based index.
   subroutine name_entry(mp, i)
      type(model_t), intent(inout) :: mp
      integer, intent(in) :: i
      character(len=24) :: idx
      write (idx, '(i0)') i - 1
      mp%errmsg = 'entry '//trim(idx)//': '//trim(mp%errmsg)
   end subroutine name_entry

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

   !> c may be NULL (no damping).
   integer(c_int) function c_model_add_stiffness_block(handle, n, nodes, k, c) &
      bind(C, name='martello_model_add_stiffness_block')
      type(c_ptr), value :: handle, c
      integer(c_int), value :: n
      integer(c_int), intent(in) :: nodes(*)
      real(c_double), intent(in) :: k(*)
      type(model_t), pointer :: mp
      real(c_double), pointer :: cp(:)
      real(dp), allocatable :: cm(:, :)
      integer :: stat
      mp => get_model(handle)
      if (.not. associated(mp) .or. n < 1) then
         c_model_add_stiffness_block = MARTELLO_ERR_ARGUMENT
         if (associated(mp)) mp%errmsg = 'add_stiffness_block: need n >= 1'
         return
      end if
      allocate (cm(n, n), stat=stat)
      if (stat /= 0) then
         call out_of_memory('the damping of a stiffness block', REAL_BYTES*n*real(n, dp), &
                            FIX_SMALLER_SCENE, stat, mp%errmsg)
         c_model_add_stiffness_block = stat; return
      end if
      cm = 0.0_dp
      if (c_associated(c)) then
         call c_f_pointer(c, cp, [n*n])
         cm = reshape(cp, [int(n), int(n)])
      end if
      call model_add_stiffness_block(mp, int(nodes(1:n)) + 1, &
                                     reshape(k(1:n*n), [int(n), int(n)]), cm, stat)
      c_model_add_stiffness_block = stat
   end function c_model_add_stiffness_block

   integer(c_int) function c_model_set_influence(handle, n, iota) bind(C, name='martello_model_set_influence')
      type(c_ptr), value :: handle
      integer(c_int), value :: n
      real(c_double), intent(in) :: iota(*)
      type(model_t), pointer :: mp
      integer :: stat
      mp => get_model(handle)
      c_model_set_influence = MARTELLO_ERR_ARGUMENT
      if (.not. associated(mp)) return
      if (n /= mp%n) then
         mp%errmsg = 'set_influence: give one value per node (n = n_nodes)'; return
      end if
      call model_set_influence(mp, iota(1:n), stat)
      c_model_set_influence = stat
   end function c_model_set_influence

   integer(c_int) function c_model_set_gravity(handle, g) bind(C, name='martello_model_set_gravity')
      type(c_ptr), value :: handle
      real(c_double), value :: g
      type(model_t), pointer :: mp
      mp => get_model(handle)
      c_model_set_gravity = MARTELLO_ERR_ARGUMENT
      if (.not. associated(mp)) return
      ! ieee_is_finite, not g /= g .or. abs(g) > huge(g): an ordered comparison with a NaN
      ! raises IEEE invalid, a trap under scripts/fpe-trap
      if (.not. ieee_is_finite(g)) then
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
      real(dp) :: no_table(0)
      mp => get_model(handle)
      if (.not. associated(mp) .or. ntab < 0) then
         c_model_add_nodal_force = MARTELLO_ERR_ARGUMENT; return
      end if
      ! a caller with no table (ntab = 0) may pass NULL: t and y are then not touched
      if (ntab == 0) then
         call model_add_nodal_force(mp, int(node) + 1, int(kind), par, no_table, no_table, stat)
      else
         call model_add_nodal_force(mp, int(node) + 1, int(kind), par, t(1:ntab), y(1:ntab), stat)
      end if
      c_model_add_nodal_force = stat
   end function c_model_add_nodal_force

   integer(c_int) function c_model_set_ground_acceleration(handle, kind, par, ntab, t, y) &
      bind(C, name='martello_model_set_ground_acceleration')
      type(c_ptr), value :: handle
      integer(c_int), value :: kind, ntab
      real(c_double), intent(in) :: par(NPAR_TF), t(*), y(*)
      type(model_t), pointer :: mp
      integer :: stat
      real(dp) :: no_table(0)
      mp => get_model(handle)
      if (.not. associated(mp) .or. ntab < 0) then
         c_model_set_ground_acceleration = MARTELLO_ERR_ARGUMENT; return
      end if
      ! a caller with no table (ntab = 0) may pass NULL: t and y are then not touched
      if (ntab == 0) then
         call model_set_ground_acceleration(mp, int(kind), par, no_table, no_table, stat)
      else
         call model_set_ground_acceleration(mp, int(kind), par, t(1:ntab), y(1:ntab), stat)
      end if
      c_model_set_ground_acceleration = stat
   end function c_model_set_ground_acceleration

   !> The effective mass m* = 1/(B M⁻¹ Bᵀ) of every contact (+inf if neither side moves).
   integer(c_int) function c_model_effective_masses(handle, mstar) &
      bind(C, name='martello_model_effective_masses')
      type(c_ptr), value :: handle
      real(c_double), intent(out) :: mstar(*)
      type(model_t), pointer :: mp
      type(model_t), allocatable :: items
      integer :: stat
      mp => get_model(handle)
      c_model_effective_masses = MARTELLO_ERR_ARGUMENT
      if (.not. associated(mp)) return
      if (any(mp%mass(1:mp%n) < 0.0_dp)) then
         mp%errmsg = 'effective_masses: every node must be set (set_node) first'
         c_model_effective_masses = MARTELLO_ERR_STATE; return
      end if
      if (mp%nchain == 0) then
         call contact_effective_masses(mp, mstar(1:mp%ncontact), mp%errmsg, stat)
      else
         ! the chains' contacts one by one, on a copy (the model keeps its chains)
         call model_expanded(mp, items, stat, mp%errmsg)
         if (stat == MARTELLO_OK) &
            call contact_effective_masses(items, mstar(1:items%ncontact), mp%errmsg, stat)
      end if
      c_model_effective_masses = stat
   end function c_model_effective_masses

   !> Copy the model's last error or warning message into buf (NUL-terminated, truncated).
   integer(c_int) function c_model_message(handle, buf, buflen) bind(C, name='martello_model_message')
      type(c_ptr), value :: handle
      integer(c_int), value :: buflen
      character(kind=c_char), intent(out) :: buf(*)
      type(model_t), pointer :: mp
      mp => get_model(handle)
      c_model_message = MARTELLO_ERR_ARGUMENT
      if (.not. associated(mp) .or. buflen < 1) return
      call copy_message(mp%errmsg, buf, buflen)
      c_model_message = MARTELLO_OK
   end function c_model_message

   integer(c_int) function c_static_solve(handle, tol, max_iter, u, force, penetration, active, &
                                          counters, conditioning) bind(C, name='martello_static_solve')
      type(c_ptr), value :: handle
      real(c_double), value :: tol
      integer(c_int), value :: max_iter
      real(c_double), intent(out) :: u(*), force(*), penetration(*), conditioning(4)
      integer(c_int), intent(out) :: active(*), counters(3)
      type(model_t), pointer :: mp, m
      type(model_t), allocatable, target :: items
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
      ! the chains' items one by one, on a copy (the model keeps its chains)
      m => mp; stat = MARTELLO_OK
      if (mp%nchain > 0) then
         call model_expanded(mp, items, stat, mp%errmsg)
         if (stat == MARTELLO_OK) m => items
      end if
      if (stat == MARTELLO_OK) call static_solve(m, tol, int(max_iter), r, stat)
      if (.not. associated(m, mp)) mp%errmsg = m%errmsg
      n = m%n; nc = m%ncontact
      if (allocated(r%u)) then
         u(1:n) = r%u; force(1:nc) = r%force; penetration(1:nc) = r%penetration
         active(1:nc) = merge(1, 0, r%active)
      end if
      counters = [r%active_set_iterations, r%uzawa_iterations, r%solves]
      conditioning = [r%rcond, r%digits_lost, r%penalty_ratio, r%penalised_rcond]
      c_static_solve = stat
   end function c_static_solve
end module martello_api_model
