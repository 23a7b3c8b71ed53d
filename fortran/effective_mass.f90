!> The effective mass of every contact and what derives from it. For contact c with row B of
!> the constraint matrix (δ = B u − gap: the contact's row, martello_element_rows — +1 at
!> node a, −1 at node b for a pair, the plan-point kinematics of two floors in general;
!> nothing for ground or a fixed node), the relative motion obeys δ̈ = −(B M⁻¹ Bᵀ) P + …, so
!> the contact sees
!>
!>   m* = 1/(B M⁻¹ Bᵀ)
!>
!> (the inverse of the contact's Delassus operator, docs/moreau-jean.md; = m_a m_b/(m_a + m_b)
!> for a diagonal M, m_a against a wall, infinite if neither side moves; for two rigid floors
!> struck at points with lever arms r1, r2 1/(1/m1 + r1²/J1 + 1/m2 + r2²/J2), the eccentric
!> effective mass of docs/buildings.md). M is the lumped
!> diagonal plus the consistent couplings (docs/p4-bars.md), restricted to the free nodes.
!> m* sets the damping of a penalty contact given a target restitution (contact_laws'
!> damping_from_restitution, docs/problems.md P5) and the Jankowski damping coefficient.
module martello_effective_mass
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_positive_inf, ieee_is_finite
   use martello_kinds, only: dp
   use martello_status
   use martello_model, only: model_t, model_bandwidth, SCHEME_PENALTY
   use martello_contact_laws, only: P_RESTITUTION, P_DAMPING, damping_from_restitution
   use martello_stability, only: free_dofs, mass_band
   use martello_lapack, only: dpbtrf, dpbtrs
   use martello_element_rows, only: row_lo, row_hi
   implicit none
   private
   public :: contact_effective_masses, effective_mass_prepare, pair_effective_mass

contains

   !> m* of every contact. A contact whose moving nodes carry no coupling sees a diagonal M,
   !> 1/m* = Σ coef²/m over its moving nodes (m_a m_b/(m_a + m_b) for a pair); otherwise M is
   !> factored once
   !> (banded Cholesky, dpbtrf) and B M⁻¹ Bᵀ solved per contact. stat = MARTELLO_ERR_ARGUMENT
   !> (message says why) if M is not positive definite on the free nodes.
   subroutine contact_effective_masses(m, mstar, message, stat)
      type(model_t), intent(in) :: m
      real(dp), intent(out) :: mstar(:)
      character(len=*), intent(inout) :: message
      integer, intent(out) :: stat
      integer, allocatable :: dof(:)
      logical, allocatable :: coupled(:)
      real(dp), allocatable :: mb(:, :), x(:)
      integer :: nf, kd, c, j, info
      call free_dofs(m, dof, nf, stat, message)
      if (stat /= MARTELLO_OK) return
      allocate (coupled(0:m%n), stat=stat)
      if (stat /= 0) then
         call out_of_memory('the coupled nodes of the effective masses', &
                            storage_size(coupled)/8*(m%n + 1.0_dp), &
                            FIX_SMALLER_SCENE, stat, message)
         return
      end if
      coupled = .false.
      do j = 1, m%ncoupling
         if (dof(m%mc_a(j)) > 0 .and. dof(m%mc_b(j)) > 0) then
            coupled(m%mc_a(j)) = .true.; coupled(m%mc_b(j)) = .true.
         end if
      end do
      kd = max(model_bandwidth(m), 0)
      if (any(coupled)) then
         call mass_band(m, dof, nf, kd, mb, stat, message)
         if (stat /= MARTELLO_OK) return
         call dpbtrf('U', nf, kd, mb, kd + 1, info)
         if (info /= 0) then
            stat = MARTELLO_ERR_ARGUMENT
            message = 'the mass matrix (node masses plus mass couplings) is not positive'// &
               ' definite: a coupling is larger than the masses it joins allow'
            return
         end if
         allocate (x(nf), stat=stat)
         if (stat /= 0) then
            call out_of_memory('a column of the inverse mass', REAL_BYTES*nf, FIX_SMALLER_SCENE, &
                               stat, message)
            return
         end if
      end if
      do c = 1, m%ncontact
         associate (nd => m%con%node(row_lo(m%con, c):row_hi(m%con, c)), &
                    cf => m%con%coef(row_lo(m%con, c):row_hi(m%con, c)))
            if (.not. any(dof(nd) > 0 .and. cf /= 0.0_dp)) then
               mstar(c) = ieee_value(1.0_dp, ieee_positive_inf)     ! nothing of it moves
            else if (size(nd) <= 2 .and. all(abs(cf) == 1.0_dp) .and. .not. any(coupled(nd))) then
               ! a node pair or a node against the ground: m_a m_b/(m_a + m_b) or m_a, as ever
               mstar(c) = pair_effective_mass(m, nd(1), merge(nd(size(nd)), 0, size(nd) == 2))
            else if (.not. any(coupled(nd))) then
               mstar(c) = 0.0_dp
               do j = 1, size(nd)
                  if (dof(nd(j)) > 0) mstar(c) = mstar(c) + cf(j)**2/m%mass(nd(j))
               end do
               mstar(c) = 1.0_dp/mstar(c)
            else
               x = 0.0_dp                ! B M⁻¹ Bᵀ = B x, x = M⁻¹ Bᵀ over the moving nodes
               do j = 1, size(nd)
                  if (dof(nd(j)) > 0) x(dof(nd(j))) = x(dof(nd(j))) + cf(j)
               end do
               call dpbtrs('U', nf, kd, 1, mb, kd + 1, x, nf, info)
               mstar(c) = 0.0_dp
               do j = 1, size(nd)
                  if (dof(nd(j)) > 0) mstar(c) = mstar(c) + cf(j)*x(dof(nd(j)))
               end do
               mstar(c) = 1.0_dp/mstar(c)
            end if
         end associate
      end do
   end subroutine contact_effective_masses

   !> m* of a contact between nodes a and b (0: ground) with no mass coupling at either:
   !> m_a m_b/(m_a + m_b), the moving side's mass against ground or a fixed node, +inf if
   !> neither side moves.
   pure real(dp) function pair_effective_mass(m, a, b) result(mstar)
      type(model_t), intent(in) :: m
      integer, intent(in) :: a, b
      logical :: ma_moves, mb_moves
      ma_moves = .false.; mb_moves = .false.
      if (a > 0) ma_moves = .not. m%fixed(a)
      if (b > 0) mb_moves = .not. m%fixed(b)
      if (.not. (ma_moves .or. mb_moves)) then
         mstar = ieee_value(1.0_dp, ieee_positive_inf)
      else if (.not. ma_moves) then
         mstar = m%mass(b)
      else if (.not. mb_moves) then
         mstar = m%mass(a)
      else
         associate (ma => m%mass(a), mbb => m%mass(b))
            mstar = ma*mbb/(ma + mbb)
         end associate
      end if
   end function pair_effective_mass

   !> What a run needs from the whole model: m%con_mstar, and the damping of every penalty
   !> contact given a target restitution, by its law's published formula. Called once the
   !> model is complete (masses and couplings are known), before the integrator starts.
   subroutine effective_mass_prepare(m, message, stat)
      type(model_t), intent(inout) :: m
      character(len=*), intent(inout) :: message
      integer, intent(out) :: stat
      integer :: c
      if (any(m%mass < 0.0_dp)) then
         stat = MARTELLO_ERR_STATE; message = 'every node must be set before a run'; return
      end if
      call contact_effective_masses(m, m%con_mstar(1:m%ncontact), message, stat)
      if (stat /= MARTELLO_OK) return
      do c = 1, m%ncontact
         if (m%con_scheme(c) /= SCHEME_PENALTY .or. m%con_par(P_RESTITUTION, c) < 0.0_dp) cycle
         ! neither side moves: the contact never acts, its damping is moot (and c·0 must stay 0)
         m%con_par(P_DAMPING, c) = 0.0_dp
         if (ieee_is_finite(m%con_mstar(c))) m%con_par(P_DAMPING, c) = &
            damping_from_restitution(m%con_law(c), m%con_par(P_RESTITUTION, c), m%con_par(:, c), &
                                     m%con_mstar(c))
      end do
   end subroutine effective_mass_prepare
end module martello_effective_mass
