!> The C door of the run handle (martello_run_create … martello_dynamic_run of c/martello.h):
!> converts arguments and calls martello_run, where validation and dispatch live.
module martello_api_run
   use, intrinsic :: iso_c_binding
   use martello_kinds, only: dp
   use martello_status
   use martello_model, only: model_t
   use martello_integrator_settings
   use martello_run, only: run_t, run_dynamic
   use martello_api_handles, only: get_model, get_run, copy_message
   implicit none
   private

contains

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

   integer(c_int) function c_dynamic_run(mhandle, rhandle) bind(C, name='martello_dynamic_run')
      type(c_ptr), value :: mhandle, rhandle
      type(model_t), pointer :: mp
      type(run_t), pointer :: rp
      integer :: stat
      mp => get_model(mhandle); rp => get_run(rhandle)
      c_dynamic_run = MARTELLO_ERR_ARGUMENT
      if (.not. associated(mp) .or. .not. associated(rp)) return
      call run_dynamic(mp, rp, stat)
      c_dynamic_run = stat
   end function c_dynamic_run

   integer(c_int) function c_run_message(handle, buf, buflen) bind(C, name='martello_run_message')
      type(c_ptr), value :: handle
      integer(c_int), value :: buflen
      character(kind=c_char), intent(out) :: buf(*)
      type(run_t), pointer :: rp
      rp => get_run(handle)
      c_run_message = MARTELLO_ERR_ARGUMENT
      if (.not. associated(rp) .or. buflen < 1) return
      call copy_message(rp%results%message, buf, buflen)
      c_run_message = MARTELLO_OK
   end function c_run_message
end module martello_api_run
