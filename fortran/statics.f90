!> Static equilibrium of any scene with unilateral contacts (docs/problems.md P1, P3; seed §3).
!> Elastic links only (springs, bars). Contacts are solved by a primal–dual active set:
!>  - lagrange: KKT system [K B; Bᵀ 0][u; P] = [f; d] (symmetric indefinite, dsytrf);
!>  - penalty (linear law, stiffness ε): the SPD penalised stiffness K + ε B Bᵀ is formed for
!>    its condition estimate (dpocon), and solved in the equivalent perturbed-Lagrangian form;
!>  - augmented-lagrange: Uzawa, P_{k+1} = max(0, P_k + ε δ(u_k)), each u_k a penalty solve
!>    shifted by P_k; converges to the Lagrange values for any finite ε.
!> A restitution contact is a rigid unilateral constraint in statics and is solved as lagrange.
!> Matrices are dense: static scenes are small (for n in the thousands use a dynamic run).
module martello_statics
   use martello_kinds, only: dp
   use martello_status
   use martello_model, only: model_t, model_influence, SCHEME_PENALTY, SCHEME_LAGRANGE, SCHEME_AUGMENTED, &
      SCHEME_RESTITUTION, model_u0
   use martello_contact_laws, only: LAW_LINEAR, P_STIFF
   use martello_links, only: LINK_SPRING, LINK_BAR, LINK_DASHPOT, LINK_FLUID_DAMPER, L_STIFF
   use martello_linalg, only: solve_spd, solve_symmetric_indefinite
   use martello_element_rows, only: rows_t, row_lo, row_hi
   use martello_time_functions, only: tf_value
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   implicit none
   private
   public :: static_result_t, static_solve

   type :: static_result_t
      real(dp), allocatable :: u(:)            !< displacement of every node
      real(dp), allocatable :: force(:)        !< contact force P >= 0 (compression)
      real(dp), allocatable :: penetration(:)  !< δ = u_a − u_b − gap
      logical, allocatable :: active(:)
      integer :: active_set_iterations = 0, uzawa_iterations = 0, solves = 0
      real(dp) :: rcond = 1.0_dp               !< LAPACK reciprocal condition estimate (1-norm)
      real(dp) :: digits_lost = 0.0_dp         !< see assess_digits
      real(dp) :: penalty_ratio = 0.0_dp       !< max ε/k over active penalty contacts
      real(dp) :: penalised_rcond = 1.0_dp     !< dpocon of K + εBBᵀ (what a primal solve faces)
   end type static_result_t

   !> Round-off allowance in the activation/release tests (in units of ε_mach × scale):
   !> without it, a grazing contact (m g = k h exactly) can flip forever on the last bit.
   real(dp), parameter :: ROUNDOFF = 64.0_dp*epsilon(1.0_dp)
   !> The fix of the out-of-memory line for the dense matrices of the static solve.
   character(len=*), parameter :: FIX_DENSE = &
      'the static solve uses dense matrices (n^2 doubles for n free nodes): use fewer nodes'

contains

   subroutine static_solve(m, tol, max_iter, r, stat)
      type(model_t), intent(inout) :: m
      real(dp), intent(in) :: tol        !< Uzawa: stop when max|ΔP| <= tol·force scale
      integer, intent(in) :: max_iter    !< bound on Uzawa and on active-set iterations
      type(static_result_t), intent(out) :: r
      integer, intent(out) :: stat

      integer :: n, nc, nf, i, j, outer, inner, nlag
      integer, allocatable :: dof(:), lag_row(:)
      real(dp), allocatable :: kfree(:, :), fext(:), p_shift(:), p_new(:), sys(:, :), rhs(:)
      logical, allocatable :: act(:), act_new(:)
      real(dp) :: kk, fscale, kscale, change, rc
      logical :: any_aug, changed

      n = m%n; nc = m%ncontact
      allocate (r%u(n), r%force(nc), r%penetration(nc), r%active(nc), dof(0:n), stat=stat)
      if (stat /= 0) then
         call no_memory('the results of the static solve', REAL_BYTES*(n + 2.0_dp*nc) &
                        + INT_BYTES*(2.0_dp*nc + n + 1), FIX_SMALLER_SCENE)
         return
      end if
      r%force = 0.0_dp; r%penetration = 0.0_dp; r%active = .false.
      stat = MARTELLO_OK

      call check_supported(m, stat)
      if (stat /= MARTELLO_OK) return

      ! Free-DOF numbering: fixed nodes keep u = u0 and leave the system.
      dof = 0; nf = 0
      do i = 1, n
         r%u(i) = merge(model_u0(m, i), 0.0_dp, m%fixed(i))
         if (.not. m%fixed(i)) then
            nf = nf + 1; dof(i) = nf
         end if
      end do

      ! Elastic stiffness and loads on the free DOFs (fixed displacements moved to the rhs).
      allocate (kfree(nf, nf), fext(nf), stat=stat)
      if (stat /= 0) then
         call no_memory('the stiffness matrix of the static solve'//of_size(nf, 0), &
                        REAL_BYTES*(nf + 1.0_dp)*nf, FIX_DENSE)
         return
      end if
      kfree = 0.0_dp; fext = 0.0_dp
      ! gravity on M·ι (ι the influence vector, 1 along the scene's axis)
      do i = 1, n
         if (dof(i) > 0) fext(dof(i)) = m%gravity*m%mass(i)*model_influence(m, i)
      end do
      do j = 1, m%ncoupling
         if (dof(m%mc_a(j)) > 0) fext(dof(m%mc_a(j))) = fext(dof(m%mc_a(j))) &
            + m%gravity*m%mc_value(j)*model_influence(m, m%mc_b(j))
         if (dof(m%mc_b(j)) > 0) fext(dof(m%mc_b(j))) = fext(dof(m%mc_b(j))) &
            + m%gravity*m%mc_value(j)*model_influence(m, m%mc_a(j))
      end do
      do j = 1, m%nforce
         i = dof(m%force_node(j))
         if (i > 0) fext(i) = fext(i) + tf_value(m%force_fn(j), 0.0_dp)
      end do
      do j = 1, m%nlink
         if (m%link_kind(j) /= LINK_SPRING .and. m%link_kind(j) /= LINK_BAR) cycle
         kk = m%link_par(L_STIFF, j)
         call add_row(kfree, fext, dof, r%u, m%lnk, j, kk)
      end do
      do j = 1, m%nblock
         call add_block(kfree, fext, dof, r%u, m%block(j)%node, m%block(j)%k)
      end do
      fscale = 1.0_dp; kscale = 1.0_dp
      if (nf > 0) then
         fscale = max(maxval(abs(fext)), tiny(1.0_dp))
         kscale = 0.0_dp
         do i = 1, nf
            kscale = max(kscale, abs(kfree(i, i)))
         end do
         if (kscale == 0.0_dp) kscale = 1.0_dp
      end if

      any_aug = any(m%con_scheme(1:nc) == SCHEME_AUGMENTED)
      allocate (act(nc), act_new(nc), p_shift(nc), p_new(nc), lag_row(nc), stat=stat)
      if (stat /= 0) then
         call no_memory('the active set of the static solve'//of_size(nf, nc), &
                        (2*REAL_BYTES + 3*INT_BYTES)*nc, FIX_SMALLER_SCENE)
         return
      end if
      act = .false.; p_shift = 0.0_dp

      do outer = 1, max_iter
         ! Primal–dual active set for the current Uzawa shift.
         do inner = 1, max_iter
            call assemble_and_solve(stat)
            if (stat == MARTELLO_ERR_SINGULAR .and. inner == 1 .and. .not. all(act)) then
               ! Without contacts the structure is a mechanism (a node held only by its
               ! contact): start again from the all-active set.
               act = .true.; stat = MARTELLO_OK; m%errmsg = ''
               call assemble_and_solve(stat)
            end if
            if (stat < 0) return
            call update_active_set(changed)
            r%active_set_iterations = r%active_set_iterations + 1
            if (.not. changed) exit
         end do
         if (changed) then
            stat = MARTELLO_ERR_NOT_CONVERGED
            m%errmsg = 'static active set did not settle within max_iter iterations'
            return
         end if
         if (.not. any_aug) exit
         ! Uzawa update of the augmented contacts' multipliers.
         r%uzawa_iterations = outer
         change = 0.0_dp
         do j = 1, nc
            if (m%con_scheme(j) /= SCHEME_AUGMENTED) cycle
            p_new(j) = max(0.0_dp, p_shift(j) + m%con_par(P_STIFF, j)*r%penetration(j))
            change = max(change, abs(p_new(j) - p_shift(j)))
            p_shift(j) = p_new(j)
            r%force(j) = p_new(j)
         end do
         if (change <= tol*max(fscale, maxval(abs(p_shift)))) exit
         if (outer == max_iter) then
            stat = MARTELLO_ERR_NOT_CONVERGED
            write (m%errmsg, '(a,i0,a,a)') 'augmented-lagrange (Uzawa) did not reach tol in ', &
               max_iter, ' iterations; last multiplier change ', sci(change, 2)
            return
         end if
      end do

      call assess_digits()

   contains

      !> An allocation failed: stat = MARTELLO_ERR_MEMORY and its line in the model's message.
      subroutine no_memory(what, bytes, fix)
         character(len=*), intent(in) :: what, fix
         real(dp), intent(in) :: bytes
         call out_of_memory(what, bytes, fix, stat, m%errmsg)
      end subroutine no_memory

      !> K(a,a) += s, K(b,b) += s, K(a,b) −= s for free ends; known displacements to the rhs.
      !> k += s gᵀg over a row's free DOFs; a term on a fixed node moves its known part to f
      !> (u fixed there).
      subroutine add_row(kmat, f, dof, u, rows, j, s)
         real(dp), intent(inout) :: kmat(:, :), f(:)
         integer, intent(in) :: dof(0:), j
         real(dp), intent(in) :: u(:), s
         type(rows_t), intent(in) :: rows
         integer :: p, q, ip, iq
         do p = row_lo(rows, j), row_hi(rows, j)
            ip = dof(rows%node(p))
            if (ip == 0) cycle
            do q = row_lo(rows, j), row_hi(rows, j)
               iq = dof(rows%node(q))
               if (iq > 0) then
                  kmat(ip, iq) = kmat(ip, iq) + s*rows%coef(p)*rows%coef(q)
               else
                  f(ip) = f(ip) - s*rows%coef(p)*rows%coef(q)*u(rows%node(q))
               end if
            end do
         end do
      end subroutine add_row

      !> A stiffness block on the free DOFs; a fixed node's prescribed u moves to the rhs.
      subroutine add_block(kmat, f, dof, u, nd, kb)
         real(dp), intent(inout) :: kmat(:, :), f(:)
         integer, intent(in) :: dof(0:), nd(:)
         real(dp), intent(in) :: u(:), kb(:, :)
         integer :: p, q, ip, iq
         do q = 1, size(nd)
            iq = dof(nd(q))
            do p = 1, size(nd)
               ip = dof(nd(p))
               if (ip == 0) cycle
               if (iq > 0) then
                  kmat(ip, iq) = kmat(ip, iq) + kb(p, q)
               else
                  f(ip) = f(ip) - kb(p, q)*u(nd(q))
               end if
            end do
         end do
      end subroutine add_block

      !> Every active contact adds a row: Bᵀu − c_j P_j = rhs_j, with B the contact's row (+1 at
      !> a, −1 at b for a pair) and
      !>  lagrange: c = 0, rhs = d;  penalty: c = 1/ε, rhs = d  (the perturbed-Lagrangian form
      !>  of the penalty method: eliminating P gives K + εBBᵀ, but the condition stays bounded
      !>  as ε → ∞, so P and δ = P/ε keep their digits);  augmented: c = 1/ε, rhs = d − P_k/ε.
      !> Rows and P are scaled by kscale (unknown P/kscale) so the matrix is equilibrated.
      subroutine assemble_and_solve(st)
         integer, intent(out) :: st
         integer :: dim, row, i, j, k, ik
         real(dp) :: dknown
         nlag = 0; lag_row = 0
         do j = 1, nc
            if (act(j) .and. any(dof(m%con%node(row_lo(m%con, j):row_hi(m%con, j))) > 0)) then
               nlag = nlag + 1; lag_row(j) = nf + nlag
            end if
         end do
         dim = nf + nlag
         if (allocated(sys)) deallocate (sys, rhs)
         allocate (sys(dim, dim), rhs(dim), stat=st)
         if (st /= 0) then
            call out_of_memory('the system of the static solve'//of_size(nf, nlag), &
                               REAL_BYTES*(dim + 1.0_dp)*dim, FIX_DENSE, st, m%errmsg)
            return
         end if
         sys = 0.0_dp; rhs = 0.0_dp
         sys(1:nf, 1:nf) = kfree; rhs(1:nf) = fext
         do j = 1, nc
            row = lag_row(j)
            if (row == 0) cycle
            ! gap minus the part of the row's Σ coef·u that is known (fixed ends)
            dknown = m%con_gap(j)
            do k = row_lo(m%con, j), row_hi(m%con, j)
               ik = dof(m%con%node(k))
               if (ik == 0) then
                  dknown = dknown - m%con%coef(k)*r%u(m%con%node(k))
               else
                  sys(ik, row) = sys(ik, row) + kscale*m%con%coef(k)
                  sys(row, ik) = sys(row, ik) + kscale*m%con%coef(k)
               end if
            end do
            rhs(row) = kscale*dknown
            if (.not. is_lagrange(j)) then
               sys(row, row) = -kscale**2/m%con_par(P_STIFF, j)
               rhs(row) = rhs(row) - kscale*p_shift(j)/m%con_par(P_STIFF, j)
            end if
         end do
         if (nlag > 0) then
            call solve_symmetric_indefinite(sys, rhs, rc, st, m%errmsg)
         else
            call solve_spd(sys, rhs, rc, st, m%errmsg)
         end if
         r%solves = r%solves + 1
         if (st /= MARTELLO_OK) return
         if (.not. all(ieee_is_finite(rhs))) then
            st = MARTELLO_ERR_SINGULAR
            m%errmsg = 'static solve produced non-finite values (singular or overflowing system)'
            return
         end if
         r%rcond = rc
         do i = 1, n
            if (dof(i) > 0) r%u(i) = rhs(dof(i))
         end do
         do j = 1, nc
            r%penetration(j) = penetration(j)
            r%force(j) = 0.0_dp
            if (lag_row(j) > 0) r%force(j) = kscale*rhs(lag_row(j))
            ! a penalty contact's δ = P/ε exactly; from u it would cancel to noise at large ε
            if (lag_row(j) > 0 .and. m%con_scheme(j) == SCHEME_PENALTY) &
               r%penetration(j) = r%force(j)/m%con_par(P_STIFF, j)
         end do
      end subroutine assemble_and_solve

      real(dp) function penetration(j)
         integer, intent(in) :: j
         integer :: k
         penetration = -m%con_gap(j)
         do k = row_lo(m%con, j), row_hi(m%con, j)
            penetration = penetration + m%con%coef(k)*r%u(m%con%node(k))
         end do
      end function penetration

      logical function is_lagrange(j)
         integer, intent(in) :: j
         is_lagrange = m%con_scheme(j) == SCHEME_LAGRANGE .or. m%con_scheme(j) == SCHEME_RESTITUTION
      end function is_lagrange

      real(dp) function length_scale(j)
         integer, intent(in) :: j
         integer :: k
         length_scale = abs(m%con_gap(j))
         do k = row_lo(m%con, j), row_hi(m%con, j)
            length_scale = length_scale + abs(m%con%coef(k)*r%u(m%con%node(k)))
         end do
      end function length_scale

      subroutine update_active_set(chg)
         logical, intent(out) :: chg
         integer :: j
         real(dp) :: trial
         do j = 1, nc
            if (act(j)) then
               ! release on tension (round-off allowance: see ROUNDOFF)
               act_new(j) = r%force(j) >= -ROUNDOFF*fscale
            else if (is_lagrange(j)) then
               act_new(j) = r%penetration(j) > ROUNDOFF*length_scale(j)
            else
               ! εδ is resolved only to ε·ulp(u): within that band a huge ε would flip the
               ! contact on the last bit, so activation needs a force beyond it
               trial = p_shift(j) + m%con_par(P_STIFF, j)*r%penetration(j)
               act_new(j) = trial > ROUNDOFF*(fscale + m%con_par(P_STIFF, j)*length_scale(j))
            end if
         end do
         chg = any(act_new .neqv. act)
         act = act_new
         r%active = act
      end subroutine update_active_set

      !> Digits lost. The system solved is well conditioned (LAPACK estimate in rcond), but a
      !> penalty stiffness ε far above the structure's stiffness k at its nodes swamps k in
      !> K + εBBᵀ: that matrix's condition (dpocon, reported too) grows like ε/k and a primal
      !> penalty code loses log10(1 + ε/k) digits — and so does u, which cannot resolve δ.
      subroutine assess_digits()
         real(dp) :: lost, ratio, kd, pen_rc
         real(dp), allocatable :: dummy(:), kpen(:, :)
         integer :: k, st, q
         allocate (dummy(max(nf, 1)), kpen(nf, nf), stat=st)
         if (st /= 0) then
            call no_memory('the penalised stiffness of the static solve'//of_size(nf, 0), &
                           REAL_BYTES*(nf + 1.0_dp)*nf, FIX_DENSE)
            return
         end if
         lost = 16.0_dp
         if (r%rcond > 0.0_dp) lost = log10(1.0_dp/r%rcond)
         r%penalty_ratio = 0.0_dp
         kpen = kfree
         do k = 1, nc
            if (.not. act(k) .or. m%con_scheme(k) /= SCHEME_PENALTY) cycle
            kd = 0.0_dp
            do q = row_lo(m%con, k), row_hi(m%con, k)
               if (dof(m%con%node(q)) > 0) kd = max(kd, kfree(dof(m%con%node(q)), dof(m%con%node(q))))
            end do
            ratio = m%con_par(P_STIFF, k)/max(kd, tiny(1.0_dp))
            r%penalty_ratio = max(r%penalty_ratio, ratio)
            call add_row(kpen, dummy, dof, r%u, m%con, k, m%con_par(P_STIFF, k))
         end do
         r%penalised_rcond = 1.0_dp
         if (r%penalty_ratio > 0.0_dp .and. nf > 0) then
            dummy = 0.0_dp
            call solve_spd(kpen, dummy(1:nf), pen_rc, st, m%errmsg)
            ! a matrix that is not positive definite has condition 0; memory running out is
            ! the solve's failure, not a condition number
            if (st == MARTELLO_ERR_MEMORY) then
               stat = st; return
            end if
            r%penalised_rcond = merge(pen_rc, 0.0_dp, st == MARTELLO_OK)
            m%errmsg = ''
            lost = max(lost, log10(1.0_dp + r%penalty_ratio))
            if (r%penalised_rcond > 0.0_dp) lost = max(lost, log10(1.0_dp/r%penalised_rcond))
         end if
         r%digits_lost = min(lost, -log10(epsilon(1.0_dp)))
         if (r%digits_lost > 8.0_dp) then
            stat = MARTELLO_ILL_CONDITIONED
            write (m%errmsg, '(a,a,a,f4.1,a)') 'ill-conditioned: penalty stiffness eps/k = ', &
               sci(r%penalty_ratio, 1), ' swamps the structure: K + eps*B*B'' loses about ', &
               r%digits_lost, ' of 16 significant digits (u cannot resolve the penetration);'// &
               ' lower eps or use scheme lagrange / augmented-lagrange'
         end if
      end subroutine assess_digits

   end subroutine static_solve

   !> ' for nf free nodes' (and nc contacts) in the out-of-memory lines of the static solve.
   function of_size(nf, nc) result(text)
      integer, intent(in) :: nf, nc
      character(len=:), allocatable :: text
      character(len=64) :: buf
      write (buf, '(a,i0,a)') ' for ', nf, ' free nodes'
      if (nc > 0) write (buf, '(a,a,i0,a)') trim(buf), ' and ', nc, ' contacts'
      text = trim(buf)
   end function of_size

   subroutine check_supported(m, stat)
      type(model_t), intent(inout) :: m
      integer, intent(out) :: stat
      integer :: j
      character(len=16) :: num
      stat = MARTELLO_OK
      do j = 1, m%nlink
         select case (m%link_kind(j))
         case (LINK_SPRING, LINK_BAR, LINK_DASHPOT, LINK_FLUID_DAMPER)
         case default
            write (num, '(i0)') j - 1
            stat = MARTELLO_ERR_UNSUPPORTED
            m%errmsg = 'link '//trim(num)//': static analysis handles elastic links (spring, bar)'// &
               ' and ignores dampers; an elasto-plastic spring needs a dynamic analysis'
            return
         end select
      end do
      do j = 1, m%ncontact
         write (num, '(i0)') j - 1
         if (m%con_scheme(j) == SCHEME_PENALTY .and. m%con_law(j) /= LAW_LINEAR) then
            stat = MARTELLO_ERR_UNSUPPORTED
            m%errmsg = 'contact '//trim(num)//': static penalty supports law linear only'// &
               ' (nonlinear laws need a dynamic analysis)'
            return
         end if
         if ((m%con_scheme(j) == SCHEME_PENALTY .or. m%con_scheme(j) == SCHEME_AUGMENTED) .and. &
             .not. m%con_par(P_STIFF, j) > 0.0_dp) then
            stat = MARTELLO_ERR_ARGUMENT
            m%errmsg = 'contact '//trim(num)//': penalty stiffness eps must be > 0'
            return
         end if
      end do
   end subroutine check_supported
end module martello_statics
