!> A dynamic run: its settings, outputs and results (run_t, what a martello_run handle points
!> to), and run_dynamic, which validates the run against the model and dispatches it to the
!> integrator. The C door (martello_api_run) only converts arguments and calls this.
module martello_run
   use, intrinsic :: iso_c_binding, only: c_int, c_ptr, c_loc, c_funptr, c_null_funptr, c_null_ptr
   use martello_kinds, only: dp
   use martello_status
   use martello_model, only: model_t, model_nlinks, model_ncontacts, model_expanded
   use martello_integrator_settings
   use martello_effective_mass, only: effective_mass_prepare
   use martello_run_checks, only: check_schemes
   use martello_observer, only: observer_t, observer_init, observer_phase_lists, observer_close, &
      functionals_t, functionals_start
   use martello_registry, only: TRACK_ALL
   use martello_fixed_step, only: run_fixed_step, stepper_t
   use martello_generalized_alpha, only: generalized_alpha_t
   use martello_central_difference, only: central_difference_t
   use martello_moreau_jean, only: moreau_jean_t
   use martello_newmark_lagrange, only: newmark_lagrange_t
   use martello_fast_nonlinear, only: fast_nonlinear_t
   use martello_registry, only: INT_FAST_NONLINEAR
   use martello_chain_step, only: chain_step_t, chain_fusable
   implicit none
   private
   public :: run_t, run_dynamic, PHASE_LISTS

   !> Contacts up to which every contact's phases are listed (docs/results.md); past it the
   !> output contacts', the others keep their first and last phase
   integer, parameter :: PHASE_LISTS = 1000

   !> Dispatched to the C integrators (c/event_driven.c, c/ida.c, c/sundials_ode.c).
   interface
      integer(c_int) function c_event_driven_run(model, run) bind(C, name='martello_event_driven_run')
         import :: c_int, c_ptr
         type(c_ptr), value :: model, run
      end function c_event_driven_run
      integer(c_int) function c_ida_run(model, run) bind(C, name='martello_ida_run')
         import :: c_int, c_ptr
         type(c_ptr), value :: model, run
      end function c_ida_run
      integer(c_int) function c_ode_run(model, run) bind(C, name='martello_ode_run')
         import :: c_int, c_ptr
         type(c_ptr), value :: model, run
      end function c_ode_run
   end interface

   type :: run_t
      type(integrator_settings_t) :: settings
      type(observer_t) :: results     !< what the run measured (martello_observer)
      integer, allocatable :: out_nodes(:), out_contacts(:), out_links(:)
      !> every contact's phases are listed while the model has at most this many contacts
      !> (< 0: always; martello_run_set_phase_lists)
      integer :: phase_lists = PHASE_LISTS
      !> what the run tracks (TRACK_* bits; martello_run_set_tracking)
      integer :: tracking = TRACK_ALL
      !> the linear functionals of the state the run tracks (martello_run_set_functionals)
      type(functionals_t) :: fq
      !> the contact whose force the step trace holds (0: no trace) and the nodes whose
      !> displacement it holds (martello_run_set_trace)
      integer :: trace_contact = 0
      integer, allocatable :: trace_nodes(:)
      logical :: configured = .false., done = .false.
      !> the caller's progress callback and its argument (martello_run_set_progress)
      type(c_funptr) :: progress = c_null_funptr
      type(c_ptr) :: progress_user = c_null_ptr
   end type run_t

contains

   !> Validate the run against the model (outputs in range, schemes runnable by the
   !> integrator, a positive definite mass matrix), derive the contacts' effective masses,
   !> size the results and run the integrator: a one-step method on the fixed-step strategy,
   !> or a C integrator (docs/run-layer.md). The caller's chains stay as they are: a method
   !> that takes items one by one runs on a copy of the model with them made into links and
   !> contacts (model_expanded), which the run owns.
   subroutine run_dynamic(mp, rp, stat)
      type(model_t), pointer, intent(in) :: mp
      type(run_t), pointer, intent(in) :: rp
      integer, intent(out) :: stat
      integer :: cap, nl, nc, st
      logical :: fused
      class(stepper_t), allocatable :: stepper
      type(model_t), allocatable, target :: expanded
      type(model_t), pointer :: m
      stat = MARTELLO_ERR_ARGUMENT
      if (.not. rp%configured) then
         rp%results%message = 'dynamic_run: call martello_run_set_settings first'
         stat = MARTELLO_ERR_STATE; return
      end if
      nl = model_nlinks(mp); nc = model_ncontacts(mp)
      if (any(rp%out_nodes < 1 .or. rp%out_nodes > mp%n) .or. &
          any(rp%out_contacts < 1 .or. rp%out_contacts > nc)) then
         rp%results%message = 'dynamic_run: an output node or contact is out of range'; return
      end if
      if (any(rp%out_links < 1 .or. rp%out_links > nl)) then
         rp%results%message = 'dynamic_run: an output link is out of range'; return
      end if
      ! the rows a fixed step records; the history starts at most at HIST_START rows of
      ! them and grows as needed (observer record)
      cap = int(min(rp%settings%t_end/rp%settings%dt/rp%settings%every + 3.0_dp, 1.0e7_dp))
      call observer_init(rp%results, rp%settings, mp%n, nc, rp%out_nodes, &
                         rp%out_contacts, cap, nl, rp%out_links, stat, rp%tracking)
      rp%results%progress = rp%progress; rp%results%progress_user = rp%progress_user
      if (stat == MARTELLO_OK) call observer_phase_lists(rp%results, rp%phase_lists, stat)
      if (stat == MARTELLO_OK .and. rp%trace_contact > nc) then
         rp%results%message = 'dynamic_run: the traced contact is out of range'
         stat = MARTELLO_ERR_ARGUMENT
      end if
      if (stat == MARTELLO_OK .and. allocated(rp%trace_nodes)) then
         if (any(rp%trace_nodes < 1 .or. rp%trace_nodes > mp%n)) then
            rp%results%message = 'dynamic_run: a traced node is out of range'
            stat = MARTELLO_ERR_ARGUMENT
         end if
      end if
      rp%results%trace_contact = rp%trace_contact
      if (allocated(rp%trace_nodes)) rp%results%trace_nodes = rp%trace_nodes
      if (stat == MARTELLO_OK .and. rp%fq%n > 0) then
         if (any(rp%fq%col < 1 .or. rp%fq%col > mp%n)) then
            rp%results%message = 'dynamic_run: a functional''s node is out of range'
            stat = MARTELLO_ERR_ARGUMENT
         else
            rp%results%fq = rp%fq
            call functionals_start(rp%results%fq, stat)
            if (stat /= 0) then
               rp%results%message = 'dynamic_run: no memory for the tracked functionals'
               stat = MARTELLO_ERR_MEMORY
            end if
         end if
      end if
      ! the chains held per node stay so for the fused chain step, which takes them whole;
      ! every other method takes their links and contacts one by one, from a copy
      m => mp
      fused = chain_fusable(mp, rp%settings) .and. .not. logical(rp%settings%event_split)
      if (stat == MARTELLO_OK .and. .not. fused .and. mp%nchain > 0) then
         call model_expanded(mp, expanded, stat, rp%results%message)
         if (stat == MARTELLO_OK) then
            m => expanded
            fused = chain_fusable(m, rp%settings) .and. .not. logical(rp%settings%event_split)
         end if
      end if
      if (stat == MARTELLO_OK) call check_schemes(m, rp%settings%kind, rp%results%message, stat)
      if (stat == MARTELLO_OK) call effective_mass_prepare(m, rp%results%message, stat)
      if (stat == MARTELLO_OK) then
         ! st: the stepper's allocation (a few hundred bytes: its arrays come at its init)
         st = 0
         select case (rp%settings%kind)
         case (INT_NEWMARK, INT_HHT, INT_GENERALIZED_ALPHA)
            if (fused) then
               allocate (chain_step_t :: stepper, stat=st)
            else
               allocate (generalized_alpha_t :: stepper, stat=st)
            end if
         case (INT_CENTRAL_DIFFERENCE)
            allocate (central_difference_t :: stepper, stat=st)
         case (INT_MOREAU_JEAN)
            allocate (moreau_jean_t :: stepper, stat=st)
         case (INT_NEWMARK_LAGRANGE)
            allocate (newmark_lagrange_t :: stepper, stat=st)
         case (INT_FAST_NONLINEAR)
            allocate (fast_nonlinear_t :: stepper, stat=st)
         case (INT_RKF45, INT_RK8PD, INT_MSBDF)
            stat = c_event_driven_run(c_loc(m), c_loc(rp))
         case (INT_IDA)
            stat = c_ida_run(c_loc(m), c_loc(rp))
         case (INT_CVODE, INT_ARKODE)
            stat = c_ode_run(c_loc(m), c_loc(rp))
         end select
         if (st /= 0) call out_of_memory('the state of the integrator', -1.0_dp, FIX_SMALLER_SCENE, &
                                         stat, rp%results%message)
         if (allocated(stepper)) call run_fixed_step(m, rp%settings, rp%results, stepper, stat)
         call observer_close(rp%results, m)
      end if
      rp%done = .true.
   end subroutine run_dynamic
end module martello_run
