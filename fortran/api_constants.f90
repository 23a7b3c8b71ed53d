!> martello_constant(): the kernels' named integer constants by name, for C and Python.
module martello_api_constants
   use, intrinsic :: iso_c_binding
   use martello_kinds, only: dp
   use martello_status
   use martello_model
   use martello_time_functions
   use martello_contact_laws
   use martello_links
   use martello_integrator_settings
   use martello_observer, only: NCOUNTERS, NENERGY, NEVENT
   implicit none
   private

contains

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
end module martello_api_constants
