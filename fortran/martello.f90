!> The module for Fortran programs: `use martello` gives what a program needs to build a
!> model and solve it statically, as the library's modules define them (docs/install.md,
!> "Fortran"): the kind dp, the status codes, the model and its constructors, the static
!> solve, and the link, contact-law, scheme and time-function constants. Parameter arrays
!> are 1-based here (par(L_STIFF)), unlike the 0-based indices of the C API (c/martello.h).
!> Dynamic runs are the C API's (martello_settings_default, martello_run_*); the module files
!> are gfortran's own format: compile with the gfortran version that built the library.
module martello
   use martello_kinds, only: dp
   use martello_status, only: MARTELLO_OK, MARTELLO_ILL_CONDITIONED, MARTELLO_ROOT_FOUND, &
      MARTELLO_ERR_ARGUMENT, MARTELLO_ERR_MEMORY, MARTELLO_ERR_SINGULAR, &
      MARTELLO_ERR_NOT_CONVERGED, MARTELLO_ERR_DIVERGED, MARTELLO_ERR_UNSUPPORTED, &
      MARTELLO_ERR_UNSTABLE, MARTELLO_ERR_LAPACK, MARTELLO_ERR_STEP_UNDERFLOW, &
      MARTELLO_ERR_EXTERNAL, MARTELLO_ERR_STATE, MARTELLO_ERR_LIMIT, MARTELLO_ERR_INTERRUPTED
   use martello_model, only: model_t, model_init, model_set_node, model_add_link, &
      model_add_contact, model_add_mass_coupling, model_add_nodal_force, &
      model_set_ground_acceleration, model_add_stiffness_block, SCHEME_PENALTY, SCHEME_LAGRANGE, SCHEME_AUGMENTED, &
      SCHEME_RESTITUTION
   use martello_statics, only: static_result_t, static_solve
   use martello_links, only: LINK_SPRING, LINK_DASHPOT, LINK_BILINEAR, LINK_FLUID_DAMPER, &
      LINK_BAR, NPAR_LINK, L_STIFF, L_DAMP, L_YIELD, L_HARDENING, L_ALPHA, L_VREG
   use martello_contact_laws, only: LAW_LINEAR, LAW_HERTZ, LAW_KELVIN, LAW_HUNT_CROSSLEY, &
      LAW_LANKARANI_NIKRAVESH, LAW_FLORES, LAW_GONTHIER, LAW_HERTZDAMP, LAW_JANKOWSKI, &
      NPAR_CONTACT, P_STIFF, P_EXPONENT, P_DAMPING, P_RESTITUTION, P_CLIP
   use martello_time_functions, only: NPAR_TF, TF_CONSTANT, TF_TABLE, TF_SINE, &
      TF_RECTANGULAR, TF_HALF_SINE
   implicit none
   public
end module martello
