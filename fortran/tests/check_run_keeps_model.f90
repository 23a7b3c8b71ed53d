!> Self-check: a run never changes the model it is given (docs/run-layer.md, "the caller's
!> model"). A chain held per node (model_add_chain) between two links added one by one is
!> run by a method that takes items one by one (HHT: on a copy with the chain made into
!> links and contacts) and by the fused chain step (Newmark, which reads the chain whole);
!> after each the model still holds its chain as it was given, and the same run made again
!> gives the same numbers to the bit (nothing of an earlier run is left in the model).
!> Built with the library's checks too (scripts/fpe-trap: -fcheck=all, the fused step and
!> the observer's bulk entry under bounds checks). Prints one line per check and "N passed,
!> M failed"; stops with status 1 if anything failed.
program check_run_keeps_model
   use, intrinsic :: iso_fortran_env, only: output_unit
   use martello_kinds, only: dp
   use martello_status, only: MARTELLO_OK
   use martello_model
   use martello_contact_laws, only: NPAR_CONTACT, LAW_LINEAR, P_STIFF
   use martello_links, only: NPAR_LINK, LINK_SPRING, L_STIFF
   use martello_integrator_settings, only: integrator_settings_t, settings_default
   use martello_registry, only: INT_NEWMARK, INT_HHT
   use martello_run_quantities, only: C_FUSED
   use martello_run, only: run_t, run_dynamic
   implicit none

   integer, parameter :: N = 12
   integer :: npass, nfail
   type(model_t), pointer :: m
   real(dp), allocatable :: k0(:), c0(:), gap0(:)
   real(dp), allocatable :: first(:), again(:)

   npass = 0; nfail = 0
   allocate (m)
   call build(m)
   k0 = m%chain(1)%k; c0 = m%chain(1)%c; gap0 = m%chain(1)%gap

   first = peaks_of(INT_HHT)
   call check_unchanged('HHT (the chain one by one, on a copy)')
   again = peaks_of(INT_HHT)
   call check(all(first == again) .and. size(first) > 0, 'HHT again: the same peaks to the bit')
   first = peaks_of(INT_NEWMARK)
   call check_unchanged('Newmark (the fused chain step, the chain whole)')
   again = peaks_of(INT_NEWMARK)
   call check(all(first == again) .and. size(first) > 0, 'Newmark again: the same peaks to the bit')

   write (output_unit, '(i0, a, i0, a)') npass, ' passed, ', nfail, ' failed'
   if (nfail > 0) then
      write (output_unit, '(a)') 'check_run_keeps_model: FAILED'
      error stop 1
   end if

contains

   !> N oscillators, the first moving towards the others: a spring to ground (k) and a
   !> dashpot (c) each, linear contacts between neighbours; a link added one by one before
   !> the chain and one after it (the numbering around a chain)
   subroutine build(m)
      type(model_t), intent(inout) :: m
      integer :: i, st
      real(dp) :: k(N), c(N), gap(N - 1), cpar(NPAR_CONTACT), lpar(NPAR_LINK)
      call model_init(m, N, 2, 0, 0, 0, st)
      do i = 1, N
         call model_set_node(m, i, 1.0_dp, 0.0_dp, merge(2.0_dp, 0.0_dp, i == 1), .false., st)
      end do
      lpar = 0.0_dp; lpar(L_STIFF) = 50.0_dp
      call model_add_link(m, LINK_SPRING, 1, 0, lpar, st)
      k = [(100.0_dp + 300.0_dp*mod(i, 2), i = 1, N)]; c = 0.5_dp
      gap = [(0.01_dp + 0.001_dp*mod(i, 3), i = 1, N - 1)]
      cpar = 0.0_dp; cpar(P_STIFF) = 1.0e4_dp
      call model_add_chain(m, 1, N, k, c=c, gap=gap, scheme=SCHEME_PENALTY, law=LAW_LINEAR, &
                           par=cpar, stat=st)
      call check(st == MARTELLO_OK, 'the model is built')
      call model_add_link(m, LINK_SPRING, N, 0, lpar, st)
   end subroutine build

   !> every node's and contact's peaks of a run of 0.5 s (Δt = 0.25 ms) with the integrator kind
   function peaks_of(kind) result(p)
      integer, intent(in) :: kind
      real(dp), allocatable :: p(:)
      type(run_t), pointer :: r
      integer :: st
      allocate (r)
      call settings_default(kind, r%settings, st)
      r%settings%dt = 2.5e-4_dp; r%settings%t_end = 0.5_dp
      allocate (r%out_nodes(0), r%out_contacts(0), r%out_links(0))
      r%configured = .true.
      call run_dynamic(m, r, st)
      call check(st == MARTELLO_OK, 'the run succeeds '//trim(r%results%message))
      if (kind == INT_NEWMARK) call check(r%results%counters(C_FUSED) > 0, &
                                          'Newmark takes the chain by the fused step')
      if (kind == INT_HHT) call check(r%results%counters(C_FUSED) == 0, 'HHT takes the general path')
      p = [r%results%u_max, r%results%u_min, r%results%v_absmax, r%results%a_absmax, &
           r%results%pen_max, r%results%force_max, r%results%link_force_absmax, &
           real(r%results%impacts, dp), r%results%energy]
      deallocate (r)
   end function peaks_of

   subroutine check_unchanged(what)
      character(len=*), intent(in) :: what
      logical :: same
      same = m%nchain == 1 .and. m%nlink == 2 .and. m%ncontact == 0
      if (same) same = allocated(m%chain(1)%k) .and. allocated(m%chain(1)%c) .and. &
                       allocated(m%chain(1)%gap)
      if (same) same = all(m%chain(1)%k == k0) .and. all(m%chain(1)%c == c0) .and. &
                       all(m%chain(1)%gap == gap0) .and. model_nlinks(m) == 2 + 2*N .and. &
                       model_ncontacts(m) == N - 1
      call check(same, 'after a run by '//what//' the model holds its chain as given')
   end subroutine check_unchanged

   subroutine check(ok, what)
      logical, intent(in) :: ok
      character(len=*), intent(in) :: what
      if (ok) then
         npass = npass + 1
         write (output_unit, '(a,a)') 'pass  ', what
      else
         nfail = nfail + 1
         write (output_unit, '(a,a)') 'FAIL  ', what
      end if
   end subroutine check
end program check_run_keeps_model
