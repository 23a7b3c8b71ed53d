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
   use martello_integrator_settings
   use martello_structural_integrators
   use martello_moreau_jean, only: run_moreau_jean
   use martello_newmark_lagrange, only: run_newmark_lagrange
   use martello_evaluator
   use martello_stability, only: mass_positive_definite
   use martello_results
   implicit none
   private
   public :: c_model_create, c_model_free

   !> Slots of the integrator parameter array of martello_run_set_integrator (0-based in C).
   integer, parameter :: NPAR_INTEGRATOR = 17
   integer, parameter :: R_DT = 1, R_T_END = 2, R_BETA = 3, R_GAMMA = 4, R_ALPHA = 5, &
                         R_RHO_INF = 6, R_TOL_RESIDUAL = 7, R_TOL_INCREMENT = 8, &
                         R_MAX_NEWTON = 9, R_CHECK_STABILITY = 10, R_EVERY = 11, &
                         R_DIVERGENCE_FACTOR = 12, R_RTOL = 13, R_ATOL = 14, R_THETA = 15, &
                         R_EVENT_TOL = 16, R_H_MAX = 17

   !> Dispatched to the C integrators (c/event_driven.c, c/ida.c).
   interface
      integer(c_int) function c_event_driven_run(model, run) bind(C, name='martello_event_driven_run')
         import :: c_int, c_ptr
         type(c_ptr), value :: model, run
      end function c_event_driven_run
      integer(c_int) function c_ida_run(model, run) bind(C, name='martello_ida_run')
         import :: c_int, c_ptr
         type(c_ptr), value :: model, run
      end function c_ida_run
   end interface

   type :: run_t
      type(integrator_settings_t) :: settings
      type(results_t) :: results
      integer, allocatable :: out_nodes(:), out_contacts(:), out_links(:)
      logical :: configured = .false., done = .false.
   end type run_t

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

   function get_run(handle) result(rp)
      type(c_ptr), value :: handle
      type(run_t), pointer :: rp
      rp => null()
      if (c_associated(handle)) call c_f_pointer(handle, rp)
   end function get_run

   integer(c_int) function c_run_create(handle) bind(C, name='martello_run_create')
      type(c_ptr), intent(out) :: handle
      type(run_t), pointer :: rp
      integer :: stat
      handle = c_null_ptr
      allocate (rp, stat=stat)
      if (stat /= 0) then
         c_run_create = MARTELLO_ERR_MEMORY; return
      end if
      allocate (rp%out_nodes(0), rp%out_contacts(0), rp%out_links(0))
      handle = c_loc(rp)
      c_run_create = MARTELLO_OK
   end function c_run_create

   subroutine c_run_free(handle) bind(C, name='martello_run_free')
      type(c_ptr), intent(inout) :: handle
      type(run_t), pointer :: rp
      rp => get_run(handle)
      if (associated(rp)) deallocate (rp)
      handle = c_null_ptr
   end subroutine c_run_free

   integer(c_int) function c_run_set_integrator(handle, kind, par) &
      bind(C, name='martello_run_set_integrator')
      type(c_ptr), value :: handle
      integer(c_int), value :: kind
      real(c_double), intent(in) :: par(NPAR_INTEGRATOR)
      type(run_t), pointer :: rp
      rp => get_run(handle)
      c_run_set_integrator = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      if (kind < INT_NEWMARK .or. kind > INT_LAST) then
         rp%results%message = 'set_integrator: unknown integrator kind'; return
      end if
      if (.not. (par(R_DT) > 0.0_dp .and. par(R_T_END) > 0.0_dp .and. par(R_EVERY) >= 1.0_dp &
                 .and. par(R_MAX_NEWTON) >= 1.0_dp .and. par(R_TOL_RESIDUAL) > 0.0_dp &
                 .and. par(R_TOL_INCREMENT) > 0.0_dp .and. par(R_DIVERGENCE_FACTOR) > 1.0_dp)) then
         rp%results%message = 'set_integrator: need dt, t_end, tolerances > 0, every and'// &
            ' max_newton >= 1, divergence_factor > 1'
         return
      end if
      if (kind == INT_NEWMARK .and. .not. (par(R_GAMMA) >= 0.0_dp .and. par(R_BETA) >= 0.0_dp)) then
         rp%results%message = 'set_integrator: Newmark needs beta >= 0 and gamma >= 0'; return
      end if
      if (kind == INT_NEWMARK .and. par(R_BETA) == 0.0_dp) then
         rp%results%message = 'set_integrator: Newmark with beta = 0 is explicit: use'// &
            ' central-difference (lumped mass, lagged damping velocity)'
         c_run_set_integrator = MARTELLO_ERR_UNSUPPORTED; return
      end if
      if (kind == INT_HHT .and. .not. (par(R_ALPHA) >= -1.0_dp/3.0_dp .and. par(R_ALPHA) <= 0.0_dp)) then
         rp%results%message = 'set_integrator: HHT alpha must lie in [-1/3, 0]'; return
      end if
      if (kind == INT_GENERALIZED_ALPHA .and. .not. (par(R_RHO_INF) >= 0.0_dp .and. par(R_RHO_INF) <= 1.0_dp)) then
         rp%results%message = 'set_integrator: generalized-alpha rho_inf must lie in [0, 1]'; return
      end if
      rp%settings%kind = kind
      rp%settings%dt = par(R_DT); rp%settings%t_end = par(R_T_END)
      rp%settings%beta = par(R_BETA); rp%settings%gamma = par(R_GAMMA)
      rp%settings%alpha = par(R_ALPHA); rp%settings%rho_inf = par(R_RHO_INF)
      rp%settings%tol_residual = par(R_TOL_RESIDUAL); rp%settings%tol_increment = par(R_TOL_INCREMENT)
      rp%settings%max_newton = nint(par(R_MAX_NEWTON))
      rp%settings%check_stability = par(R_CHECK_STABILITY) /= 0.0_dp
      rp%settings%every = nint(par(R_EVERY))
      rp%settings%divergence_factor = par(R_DIVERGENCE_FACTOR)
      rp%settings%rtol = par(R_RTOL); rp%settings%atol = par(R_ATOL)
      rp%settings%theta = par(R_THETA); rp%settings%event_tol = par(R_EVENT_TOL)
      rp%settings%h_max = par(R_H_MAX)
      rp%configured = .true.
      c_run_set_integrator = MARTELLO_OK
   end function c_run_set_integrator

   !> Which links the history records (0-based): their force and elongation.
   integer(c_int) function c_run_set_link_outputs(handle, nl, links) bind(C, name='martello_run_set_link_outputs')
      type(c_ptr), value :: handle
      integer(c_int), value :: nl
      integer(c_int), intent(in) :: links(*)
      type(run_t), pointer :: rp
      rp => get_run(handle)
      c_run_set_link_outputs = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp) .or. nl < 0) return
      rp%out_links = links(1:nl) + 1
      c_run_set_link_outputs = MARTELLO_OK
   end function c_run_set_link_outputs

   !> Per link: max |force| and max |elongation| over the run (NaN if not tracked).
   integer(c_int) function c_run_link_peaks(handle, fmax, dumax) bind(C, name='martello_run_link_peaks')
      type(c_ptr), value :: handle
      real(c_double), intent(out) :: fmax(*), dumax(*)
      type(run_t), pointer :: rp
      integer :: nl
      rp => get_run(handle)
      c_run_link_peaks = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      if (.not. allocated(rp%results%link_force_absmax)) return
      nl = size(rp%results%link_force_absmax)
      fmax(1:nl) = rp%results%link_force_absmax; dumax(1:nl) = rp%results%link_du_absmax
      c_run_link_peaks = MARTELLO_OK
   end function c_run_link_peaks

   !> Which nodes and contacts the history records (0-based); the peaks cover all of them.
   integer(c_int) function c_run_set_outputs(handle, nn, nodes, nc, contacts) &
      bind(C, name='martello_run_set_outputs')
      type(c_ptr), value :: handle
      integer(c_int), value :: nn, nc
      integer(c_int), intent(in) :: nodes(*), contacts(*)
      type(run_t), pointer :: rp
      rp => get_run(handle)
      c_run_set_outputs = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp) .or. nn < 0 .or. nc < 0) return
      rp%out_nodes = nodes(1:nn) + 1
      rp%out_contacts = contacts(1:nc) + 1
      c_run_set_outputs = MARTELLO_OK
   end function c_run_set_outputs

   integer(c_int) function c_dynamic_run(mhandle, rhandle) bind(C, name='martello_dynamic_run')
      type(c_ptr), value :: mhandle, rhandle
      type(model_t), pointer :: mp
      type(run_t), pointer :: rp
      integer :: stat, cap
      mp => get_model(mhandle); rp => get_run(rhandle)
      c_dynamic_run = MARTELLO_ERR_ARGUMENT
      if (.not. associated(mp) .or. .not. associated(rp)) return
      if (.not. rp%configured) then
         rp%results%message = 'dynamic_run: call martello_run_set_integrator first'
         c_dynamic_run = MARTELLO_ERR_STATE; return
      end if
      if (any(rp%out_nodes < 1 .or. rp%out_nodes > mp%n) .or. &
          any(rp%out_contacts < 1 .or. rp%out_contacts > mp%ncontact)) then
         rp%results%message = 'dynamic_run: an output node or contact is out of range'; return
      end if
      cap = int(min(rp%settings%t_end/rp%settings%dt/rp%settings%every + 3.0_dp, 1.0e7_dp))
      if (any(rp%out_links < 1 .or. rp%out_links > mp%nlink)) then
         rp%results%message = 'dynamic_run: an output link is out of range'; return
      end if
      call results_init(rp%results, mp%n, mp%ncontact, rp%out_nodes, rp%out_contacts, cap, &
                        mp%nlink, rp%out_links)
      call check_compatibility(mp, rp, stat)
      if (stat == MARTELLO_OK .and. mp%ncoupling > 0) then
         if (.not. mass_positive_definite(mp)) then
            stat = MARTELLO_ERR_ARGUMENT
            rp%results%message = 'the mass matrix (node masses plus mass couplings) is not'// &
               ' positive definite: a coupling is larger than the masses it joins allow'
         end if
      end if
      if (stat == MARTELLO_OK) then
         select case (rp%settings%kind)
         case (INT_NEWMARK, INT_HHT, INT_GENERALIZED_ALPHA, INT_CENTRAL_DIFFERENCE)
            call run_structural(mp, rp%settings, rp%results, stat)
         case (INT_MOREAU_JEAN)
            call run_moreau_jean(mp, rp%settings, rp%results, stat)
         case (INT_NEWMARK_LAGRANGE)
            call run_newmark_lagrange(mp, rp%settings, rp%results, stat)
         case (INT_RKF45, INT_RK8PD, INT_MSBDF)
            stat = c_event_driven_run(mhandle, rhandle)
         case (INT_IDA)
            stat = c_ida_run(mhandle, rhandle)
         end select
      end if
      rp%done = .true.
      c_dynamic_run = stat
   end function c_dynamic_run

   !> Every contact's scheme must run on the chosen integrator; the error names those that
   !> would (the compatibility table of martello_integrator_settings).
   subroutine check_compatibility(mp, rp, stat)
      type(model_t), intent(in) :: mp
      type(run_t), intent(inout) :: rp
      integer, intent(out) :: stat
      integer :: j, k
      character(len=16) :: num
      character(len=256) :: works
      stat = MARTELLO_OK
      do j = 1, mp%ncontact
         if (scheme_supported(rp%settings%kind, mp%con_scheme(j))) cycle
         works = ''
         do k = 1, INT_LAST
            if (scheme_supported(k, mp%con_scheme(j))) works = trim(works)//' '//integrator_name(k)
         end do
         write (num, '(i0)') j - 1
         stat = MARTELLO_ERR_UNSUPPORTED
         rp%results%message = 'contact '//trim(num)//': scheme '//scheme_name(mp%con_scheme(j))// &
            ' cannot run on '//integrator_name(rp%settings%kind)//'; integrators that can:'//trim(works)
         if (len_trim(works) == 0) rp%results%message = 'contact '//trim(num)//': scheme '// &
            scheme_name(mp%con_scheme(j))//' is static only; use analysis type static'
         return
      end do
   end subroutine check_compatibility

   ! ---- the door for the C integrators (c/martello_internal.h) -----------------------------

   integer(c_int) function c_model_topology(handle, n, nc, mass, fixed, con_a, con_b, scheme, &
                                            gap, restitution, ncoupling) bind(C, name='martello_model_topology')
      type(c_ptr), value :: handle
      integer(c_int), intent(out) :: n, nc, ncoupling
      type(c_ptr), value :: mass, fixed, con_a, con_b, scheme, gap, restitution
      type(model_t), pointer :: mp
      real(c_double), pointer :: pm(:), pg(:), pe(:)
      integer(c_int), pointer :: pf(:), pa(:), pb(:), ps(:)
      mp => get_model(handle)
      c_model_topology = MARTELLO_ERR_ARGUMENT
      if (.not. associated(mp)) return
      n = mp%n; nc = mp%ncontact; ncoupling = mp%ncoupling
      if (c_associated(mass)) then
         call c_f_pointer(mass, pm, [n]); pm = mp%mass
      end if
      if (c_associated(fixed)) then
         call c_f_pointer(fixed, pf, [n]); pf = merge(1, 0, mp%fixed)
      end if
      if (nc > 0) then
         if (c_associated(con_a)) then
            call c_f_pointer(con_a, pa, [nc]); pa = mp%con_a(1:nc) - 1
         end if
         if (c_associated(con_b)) then
            call c_f_pointer(con_b, pb, [nc]); pb = mp%con_b(1:nc) - 1
         end if
         if (c_associated(scheme)) then
            call c_f_pointer(scheme, ps, [nc]); ps = mp%con_scheme(1:nc)
         end if
         if (c_associated(gap)) then
            call c_f_pointer(gap, pg, [nc]); pg = mp%con_gap(1:nc)
         end if
         if (c_associated(restitution)) then
            call c_f_pointer(restitution, pe, [nc]); pe = mp%con_par(P_RESTITUTION, 1:nc)
         end if
      end if
      c_model_topology = MARTELLO_OK
   end function c_model_topology

   !> Initial displacements and velocities of the nodes (fixed nodes: u0, v = 0).
   integer(c_int) function c_model_initial_state(handle, u0, v0) bind(C, name='martello_model_initial_state')
      type(c_ptr), value :: handle
      real(c_double), intent(out) :: u0(*), v0(*)
      type(model_t), pointer :: mp
      mp => get_model(handle)
      c_model_initial_state = MARTELLO_ERR_ARGUMENT
      if (.not. associated(mp)) return
      u0(1:mp%n) = mp%u0
      v0(1:mp%n) = merge(0.0_dp, mp%v0, mp%fixed)
      c_model_initial_state = MARTELLO_OK
   end function c_model_initial_state

   !> The force of every penalty contact at the last evaluation (0 for other schemes).
   integer(c_int) function c_eval_contact_forces(handle, force) bind(C, name='martello_eval_contact_forces')
      type(c_ptr), value :: handle
      real(c_double), intent(out) :: force(*)
      type(evaluator_t), pointer :: ep
      integer :: nc
      ep => get_eval(handle)
      c_eval_contact_forces = MARTELLO_ERR_ARGUMENT
      if (.not. associated(ep)) return
      nc = ep%m%ncontact
      force(1:nc) = merge(ep%ms%con_f_trial(1:nc), 0.0_dp, ep%ms%is_penalty(1:nc))
      c_eval_contact_forces = MARTELLO_OK
   end function c_eval_contact_forces

   function get_eval(handle) result(ep)
      type(c_ptr), value :: handle
      type(evaluator_t), pointer :: ep
      ep => null()
      if (c_associated(handle)) call c_f_pointer(handle, ep)
   end function get_eval

   integer(c_int) function c_eval_create(mhandle, handle) bind(C, name='martello_eval_create')
      type(c_ptr), value :: mhandle
      type(c_ptr), intent(out) :: handle
      type(model_t), pointer :: mp
      type(evaluator_t), pointer :: ep
      handle = c_null_ptr
      mp => get_model(mhandle)
      c_eval_create = MARTELLO_ERR_ARGUMENT
      if (.not. associated(mp)) return
      allocate (ep)
      call evaluator_init(ep, mp)
      handle = c_loc(ep)
      c_eval_create = MARTELLO_OK
   end function c_eval_create

   subroutine c_eval_free(handle) bind(C, name='martello_eval_free')
      type(c_ptr), intent(inout) :: handle
      type(evaluator_t), pointer :: ep
      ep => get_eval(handle)
      if (associated(ep)) deallocate (ep)
      handle = c_null_ptr
   end subroutine c_eval_free

   integer(c_int) function c_eval_acceleration(handle, t, u, v, a) bind(C, name='martello_eval_acceleration')
      type(c_ptr), value :: handle
      real(c_double), value :: t
      real(c_double), intent(in) :: u(*), v(*)
      real(c_double), intent(out) :: a(*)
      type(evaluator_t), pointer :: ep
      logical :: ok
      ep => get_eval(handle)
      c_eval_acceleration = MARTELLO_ERR_ARGUMENT
      if (.not. associated(ep)) return
      call evaluator_acceleration(ep, t, u(1:ep%m%n), v(1:ep%m%n), a(1:ep%m%n), ok)
      c_eval_acceleration = merge(MARTELLO_OK, MARTELLO_ERR_SINGULAR, ok)
   end function c_eval_acceleration

   integer(c_int) function c_eval_forces(handle, t, u, v, fint, fext) bind(C, name='martello_eval_forces')
      type(c_ptr), value :: handle
      real(c_double), value :: t
      real(c_double), intent(in) :: u(*), v(*)
      real(c_double), intent(out) :: fint(*), fext(*)
      type(evaluator_t), pointer :: ep
      ep => get_eval(handle)
      c_eval_forces = MARTELLO_ERR_ARGUMENT
      if (.not. associated(ep)) return
      call evaluator_forces(ep, t, u(1:ep%m%n), v(1:ep%m%n), fint(1:ep%m%n), fext(1:ep%m%n))
      c_eval_forces = MARTELLO_OK
   end function c_eval_forces

   integer(c_int) function c_eval_solve_mass(handle, x) bind(C, name='martello_eval_solve_mass')
      type(c_ptr), value :: handle
      real(c_double), intent(inout) :: x(*)
      type(evaluator_t), pointer :: ep
      logical :: ok
      ep => get_eval(handle)
      c_eval_solve_mass = MARTELLO_ERR_ARGUMENT
      if (.not. associated(ep)) return
      call evaluator_solve_mass(ep, x(1:ep%m%n), ok)
      c_eval_solve_mass = merge(MARTELLO_OK, MARTELLO_ERR_SINGULAR, ok)
   end function c_eval_solve_mass

   integer(c_int) function c_eval_contacts(handle, u, v, pen, rate) bind(C, name='martello_eval_contacts')
      type(c_ptr), value :: handle
      real(c_double), intent(in) :: u(*), v(*)
      real(c_double), intent(out) :: pen(*), rate(*)
      type(evaluator_t), pointer :: ep
      ep => get_eval(handle)
      c_eval_contacts = MARTELLO_ERR_ARGUMENT
      if (.not. associated(ep)) return
      call evaluator_contacts(ep, u(1:ep%m%n), v(1:ep%m%n), pen(1:ep%m%ncontact), rate(1:ep%m%ncontact))
      c_eval_contacts = MARTELLO_OK
   end function c_eval_contacts

   integer(c_int) function c_eval_commit(handle, u, v) bind(C, name='martello_eval_commit')
      type(c_ptr), value :: handle
      real(c_double), intent(in) :: u(*), v(*)
      type(evaluator_t), pointer :: ep
      ep => get_eval(handle)
      c_eval_commit = MARTELLO_ERR_ARGUMENT
      if (.not. associated(ep)) return
      call evaluator_commit(ep, u(1:ep%m%n), v(1:ep%m%n))
      c_eval_commit = MARTELLO_OK
   end function c_eval_commit

   integer(c_int) function c_eval_energy(handle, u, v, kinetic, recoverable) bind(C, name='martello_eval_energy')
      type(c_ptr), value :: handle
      real(c_double), intent(in) :: u(*), v(*)
      real(c_double), intent(out) :: kinetic, recoverable
      type(evaluator_t), pointer :: ep
      ep => get_eval(handle)
      c_eval_energy = MARTELLO_ERR_ARGUMENT
      if (.not. associated(ep)) return
      call evaluator_energy(ep, u(1:ep%m%n), v(1:ep%m%n), kinetic, recoverable)
      c_eval_energy = MARTELLO_OK
   end function c_eval_energy

   integer(c_int) function c_run_settings(handle, kind, par) bind(C, name='martello_run_settings')
      type(c_ptr), value :: handle
      integer(c_int), intent(out) :: kind
      real(c_double), intent(out) :: par(NPAR_INTEGRATOR)
      type(run_t), pointer :: rp
      rp => get_run(handle)
      c_run_settings = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      associate (st => rp%settings)
         kind = st%kind
         par = 0.0_c_double
         par(R_DT) = st%dt; par(R_T_END) = st%t_end; par(R_BETA) = st%beta
         par(R_GAMMA) = st%gamma; par(R_ALPHA) = st%alpha; par(R_RHO_INF) = st%rho_inf
         par(R_TOL_RESIDUAL) = st%tol_residual; par(R_TOL_INCREMENT) = st%tol_increment
         par(R_MAX_NEWTON) = st%max_newton; par(R_CHECK_STABILITY) = merge(1, 0, st%check_stability)
         par(R_EVERY) = st%every; par(R_DIVERGENCE_FACTOR) = st%divergence_factor
         par(R_RTOL) = st%rtol; par(R_ATOL) = st%atol; par(R_THETA) = st%theta
         par(R_EVENT_TOL) = st%event_tol; par(R_H_MAX) = st%h_max
      end associate
      c_run_settings = MARTELLO_OK
   end function c_run_settings

   !> (Re)initialise the run's results for the model (the dispatcher already did; C
   !> integrators may call it to start over).
   integer(c_int) function c_run_begin(handle, mhandle) bind(C, name='martello_run_begin')
      type(c_ptr), value :: handle, mhandle
      type(run_t), pointer :: rp
      type(model_t), pointer :: mp
      rp => get_run(handle); mp => get_model(mhandle)
      c_run_begin = MARTELLO_ERR_ARGUMENT
      if (.not. (associated(rp) .and. associated(mp))) return
      call results_init(rp%results, mp%n, mp%ncontact, rp%out_nodes, rp%out_contacts, 1024, &
                        mp%nlink, rp%out_links)
      c_run_begin = MARTELLO_OK
   end function c_run_begin

   integer(c_int) function c_run_track(handle, t, u, v, a, pen, force) bind(C, name='martello_run_track')
      type(c_ptr), value :: handle
      real(c_double), value :: t
      real(c_double), intent(in) :: u(*), v(*), a(*), pen(*), force(*)
      type(run_t), pointer :: rp
      integer :: n, nc
      rp => get_run(handle)
      c_run_track = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      n = size(rp%results%u_max); nc = size(rp%results%pen_max)
      call results_track(rp%results, t, u(1:n), v(1:n), a(1:n), pen(1:nc), force(1:nc))
      c_run_track = MARTELLO_OK
   end function c_run_track

   integer(c_int) function c_run_record(handle, t, u, v, a, pen, force, energy) bind(C, name='martello_run_record')
      type(c_ptr), value :: handle
      real(c_double), value :: t
      real(c_double), intent(in) :: u(*), v(*), a(*), pen(*), force(*), energy(NENERGY)
      type(run_t), pointer :: rp
      integer :: n, nc
      rp => get_run(handle)
      c_run_record = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      n = size(rp%results%u_max); nc = size(rp%results%pen_max)
      call results_record(rp%results, t, u(1:n), v(1:n), a(1:n), pen(1:nc), force(1:nc), energy)
      rp%results%energy = energy
      rp%results%energy_balance_max = max(rp%results%energy_balance_max, abs(energy(E_BALANCE)))
      c_run_record = MARTELLO_OK
   end function c_run_record

   integer(c_int) function c_run_add_event(handle, contact, values) bind(C, name='martello_run_add_event')
      type(c_ptr), value :: handle
      integer(c_int), value :: contact
      real(c_double), intent(in) :: values(NEVENT)
      type(run_t), pointer :: rp
      rp => get_run(handle)
      c_run_add_event = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      if (contact < 0 .or. contact >= size(rp%results%impacts)) return
      call results_add_event(rp%results, int(contact) + 1, values)
      rp%results%impacts(contact + 1) = rp%results%impacts(contact + 1) + 1
      c_run_add_event = MARTELLO_OK
   end function c_run_add_event

   integer(c_int) function c_run_add_counts(handle, inc) bind(C, name='martello_run_add_counts')
      type(c_ptr), value :: handle
      integer(c_long_long), intent(in) :: inc(NCOUNTERS)
      type(run_t), pointer :: rp
      rp => get_run(handle)
      c_run_add_counts = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      rp%results%counters = rp%results%counters + inc
      c_run_add_counts = MARTELLO_OK
   end function c_run_add_counts

   integer(c_int) function c_run_set_message(handle, msg) bind(C, name='martello_run_set_message')
      type(c_ptr), value :: handle
      character(kind=c_char), intent(in) :: msg(*)
      type(run_t), pointer :: rp
      integer :: i
      rp => get_run(handle)
      c_run_set_message = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      rp%results%message = ''
      do i = 1, len(rp%results%message)
         if (msg(i) == c_null_char) exit
         rp%results%message(i:i) = msg(i)
      end do
      c_run_set_message = MARTELLO_OK
   end function c_run_set_message

   integer(c_int) function c_run_finish(handle, t_reached, energy, balance_max) bind(C, name='martello_run_finish')
      type(c_ptr), value :: handle
      real(c_double), value :: t_reached, balance_max
      real(c_double), intent(in) :: energy(NENERGY)
      type(run_t), pointer :: rp
      rp => get_run(handle)
      c_run_finish = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      rp%results%t_end_reached = t_reached
      rp%results%energy = energy
      rp%results%energy_balance_max = max(rp%results%energy_balance_max, balance_max)
      c_run_finish = MARTELLO_OK
   end function c_run_finish

   integer(c_int) function c_run_message(handle, buf, buflen) bind(C, name='martello_run_message')
      type(c_ptr), value :: handle
      integer(c_int), value :: buflen
      character(kind=c_char), intent(out) :: buf(*)
      type(run_t), pointer :: rp
      integer :: i, n
      rp => get_run(handle)
      c_run_message = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp) .or. buflen < 1) return
      n = min(len_trim(rp%results%message), int(buflen) - 1)
      do i = 1, n
         buf(i) = rp%results%message(i:i)
      end do
      buf(n + 1) = c_null_char
      c_run_message = MARTELLO_OK
   end function c_run_message

   integer(c_int) function c_run_history_shape(handle, rows, cols) bind(C, name='martello_run_history_shape')
      type(c_ptr), value :: handle
      integer(c_int), intent(out) :: rows, cols
      type(run_t), pointer :: rp
      rp => get_run(handle)
      rows = 0; cols = 0
      c_run_history_shape = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      rows = rp%results%nrec; cols = rp%results%ncol
      c_run_history_shape = MARTELLO_OK
   end function c_run_history_shape

   !> The history, one record after the other (C row-major rows × cols).
   integer(c_int) function c_run_history(handle, buf) bind(C, name='martello_run_history')
      type(c_ptr), value :: handle
      real(c_double), intent(out) :: buf(*)
      type(run_t), pointer :: rp
      integer :: nr, nc
      rp => get_run(handle)
      c_run_history = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      nr = rp%results%nrec; nc = rp%results%ncol
      if (nr > 0) buf(1:nr*nc) = reshape(rp%results%hist(:, 1:nr), [nr*nc])
      c_run_history = MARTELLO_OK
   end function c_run_history

   !> Contact phases: n on return; if contacts is not NULL also contact[n] (0-based) and
   !> values[n][6] = {t_on, t_off (−1: still open at the end), v_in, v_out, max δ, max P}.
   integer(c_int) function c_run_events(handle, n, contacts, values) bind(C, name='martello_run_events')
      type(c_ptr), value :: handle
      integer(c_int), intent(out) :: n
      type(c_ptr), value :: contacts, values
      type(run_t), pointer :: rp
      integer(c_int), pointer :: ic(:)
      real(c_double), pointer :: vals(:, :)
      rp => get_run(handle)
      n = 0
      c_run_events = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      n = rp%results%nevents
      if (c_associated(contacts) .and. n > 0) then
         call c_f_pointer(contacts, ic, [n])
         ic = rp%results%ev_contact(1:n) - 1
      end if
      if (c_associated(values) .and. n > 0) then
         call c_f_pointer(values, vals, [NEVENT, n])
         vals = rp%results%ev(:, 1:n)
      end if
      c_run_events = MARTELLO_OK
   end function c_run_events

   !> counters[9] = {steps, rejected steps, Newton iterations, residual evaluations,
   !> factorizations, events, Jacobian evaluations, root-function evaluations, chatter}
   integer(c_int) function c_run_counters(handle, counters) bind(C, name='martello_run_counters')
      type(c_ptr), value :: handle
      integer(c_long_long), intent(out) :: counters(NCOUNTERS)
      type(run_t), pointer :: rp
      rp => get_run(handle)
      c_run_counters = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      counters = rp%results%counters
      c_run_counters = MARTELLO_OK
   end function c_run_counters

   integer(c_int) function c_run_peaks(handle, u_max, u_min, v_absmax, a_absmax, pen_max, &
                                       force_max, impacts, u_peak, t_peak) bind(C, name='martello_run_peaks')
      type(c_ptr), value :: handle
      real(c_double), intent(out) :: u_max(*), u_min(*), v_absmax(*), a_absmax(*), pen_max(*), &
                                     force_max(*), u_peak(*), t_peak(*)
      integer(c_int), intent(out) :: impacts(*)
      type(run_t), pointer :: rp
      integer :: n, nc
      rp => get_run(handle)
      c_run_peaks = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      if (.not. allocated(rp%results%u_max)) return
      n = size(rp%results%u_max); nc = size(rp%results%pen_max)
      u_max(1:n) = rp%results%u_max; u_min(1:n) = rp%results%u_min
      v_absmax(1:n) = rp%results%v_absmax; a_absmax(1:n) = rp%results%a_absmax
      pen_max(1:nc) = rp%results%pen_max; force_max(1:nc) = rp%results%force_max
      impacts(1:nc) = rp%results%impacts
      u_peak(1:n) = rp%results%u_peak; t_peak(1:n) = rp%results%t_peak
      c_run_peaks = MARTELLO_OK
   end function c_run_peaks

   !> energy[9] = {kinetic, recoverable, input, damping, plastic, contact, balance, initial,
   !> impact}; extra[4] = {max |balance| over the run, omega_max, dt_crit, t reached}
   integer(c_int) function c_run_energy(handle, energy, extra) bind(C, name='martello_run_energy')
      type(c_ptr), value :: handle
      real(c_double), intent(out) :: energy(NENERGY), extra(4)
      type(run_t), pointer :: rp
      rp => get_run(handle)
      c_run_energy = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp)) return
      energy = rp%results%energy
      extra = [rp%results%energy_balance_max, rp%results%omega_max, rp%results%dt_critical, &
               rp%results%t_end_reached]
      c_run_energy = MARTELLO_OK
   end function c_run_energy

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
      case ('INT_NEWMARK'); v = INT_NEWMARK
      case ('INT_HHT'); v = INT_HHT
      case ('INT_GENERALIZED_ALPHA'); v = INT_GENERALIZED_ALPHA
      case ('INT_CENTRAL_DIFFERENCE'); v = INT_CENTRAL_DIFFERENCE
      case ('INT_MOREAU_JEAN'); v = INT_MOREAU_JEAN
      case ('INT_NEWMARK_LAGRANGE'); v = INT_NEWMARK_LAGRANGE
      case ('INT_RKF45'); v = INT_RKF45
      case ('INT_RK8PD'); v = INT_RK8PD
      case ('INT_MSBDF'); v = INT_MSBDF
      case ('INT_IDA'); v = INT_IDA
      case ('R_RTOL'); v = R_RTOL - 1
      case ('R_ATOL'); v = R_ATOL - 1
      case ('R_THETA'); v = R_THETA - 1
      case ('R_EVENT_TOL'); v = R_EVENT_TOL - 1
      case ('R_H_MAX'); v = R_H_MAX - 1
      case ('NPAR_INTEGRATOR'); v = NPAR_INTEGRATOR
      case ('R_DT'); v = R_DT - 1
      case ('R_T_END'); v = R_T_END - 1
      case ('R_BETA'); v = R_BETA - 1
      case ('R_GAMMA'); v = R_GAMMA - 1
      case ('R_ALPHA'); v = R_ALPHA - 1
      case ('R_RHO_INF'); v = R_RHO_INF - 1
      case ('R_TOL_RESIDUAL'); v = R_TOL_RESIDUAL - 1
      case ('R_TOL_INCREMENT'); v = R_TOL_INCREMENT - 1
      case ('R_MAX_NEWTON'); v = R_MAX_NEWTON - 1
      case ('R_CHECK_STABILITY'); v = R_CHECK_STABILITY - 1
      case ('R_EVERY'); v = R_EVERY - 1
      case ('R_DIVERGENCE_FACTOR'); v = R_DIVERGENCE_FACTOR - 1
      case ('NCOUNTERS'); v = NCOUNTERS
      case ('NENERGY'); v = NENERGY
      case ('NEVENT'); v = NEVENT
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
