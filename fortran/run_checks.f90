!> Checks of a run before it starts: the settings and the scene, one wording for every
!> integrator (divergence during a run is the observer's, martello_observer).
module martello_run_checks
   use martello_kinds, only: dp
   use martello_status
   use martello_model, only: model_t, scheme_name
   use martello_integrator_settings, only: integrator_settings_t, integrator_name, scheme_supported, INT_LAST, &
      INT_MOREAU_JEAN
   use martello_registry, only: SCHEME_PENALTY
   use martello_contact_laws, only: LAW_JANKOWSKI
   implicit none
   private
   public :: check_run_settings, check_schemes

contains

   !> Every contact's scheme runnable by the integrator; every node set (the settings were
   !> validated by settings_check). stat /= MARTELLO_OK with message saying which.
   subroutine check_run_settings(m, s, message, stat)
      type(model_t), intent(in) :: m
      type(integrator_settings_t), intent(in) :: s
      character(len=*), intent(inout) :: message
      integer, intent(out) :: stat
      call check_schemes(m, s%kind, message, stat)
      if (stat /= MARTELLO_OK) return
      if (any(m%mass < 0.0_dp)) then
         stat = MARTELLO_ERR_STATE; message = 'every node must be set before a run'
      end if
   end subroutine check_run_settings

   !> Every contact's scheme must run on the integrator kind; the message names the
   !> integrators that would (the compatibility table of martello_integrator_settings).
   subroutine check_schemes(m, kind, message, stat)
      type(model_t), intent(in) :: m
      integer, intent(in) :: kind
      character(len=*), intent(inout) :: message
      integer, intent(out) :: stat
      integer :: j, k
      character(len=16) :: num
      character(len=256) :: works
      stat = MARTELLO_OK
      do j = 1, m%ncontact
         if (scheme_supported(kind, m%con_scheme(j))) cycle
         works = ''
         do k = 1, INT_LAST
            if (scheme_supported(k, m%con_scheme(j))) works = trim(works)//' '//integrator_name(k)
         end do
         write (num, '(i0)') j - 1
         stat = MARTELLO_ERR_UNSUPPORTED
         message = 'contact '//trim(num)//': scheme '//scheme_name(m%con_scheme(j))// &
            ' cannot run on '//integrator_name(kind)//'; integrators that can:'//trim(works)
         if (len_trim(works) == 0) message = 'contact '//trim(num)//': scheme '// &
            scheme_name(m%con_scheme(j))//' is static only; use analysis type static'
         return
      end do
      ! Moreau-Jean linearises the smooth forces once per step with the start-of-step
      ! tangent (docs/moreau-jean.md); Jankowski's dF/d(delta) is unbounded at first touch,
      ! so the step overshoots and the impact comes out elastic (e near 1 for a target 0.65,
      ! docs/behaviour.md): refused, not run wrong
      if (kind == INT_MOREAU_JEAN) then
         do j = 1, m%ncontact
            if (m%con_scheme(j) /= SCHEME_PENALTY .or. m%con_law(j) /= LAW_JANKOWSKI) cycle
            write (num, '(i0)') j - 1
            stat = MARTELLO_ERR_UNSUPPORTED
            message = 'contact '//trim(num)//': law jankowski cannot run on moreau-jean '// &
               '(its one linearisation per step misses the unbounded stiffness at first touch); '// &
               'use newmark, hht, generalized-alpha, central-difference, rkf45, rk8pd, msbdf or ida'
            return
         end do
      end if
   end subroutine check_schemes
end module martello_run_checks
