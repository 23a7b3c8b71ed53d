!> The highest natural frequency ω_max of the linearised scene (initial link stiffnesses plus
!> every linear/Kelvin penalty contact as if closed), from the banded generalized symmetric
!> eigenproblem K φ = ω² M φ on the free DOFs (LAPACK dsbgvx, largest eigenvalue only: O(n)
!> for a chain). It gives the explicit central-difference limit Δt_crit = 2/ω_max.
!> Hertz-type laws have zero stiffness at first touch and are left out: their limit depends
!> on the penetration, so only the run-time divergence detector guards them.
module martello_stability
   use martello_kinds, only: dp
   use martello_lapack, only: dsbgvx
   use martello_model, only: model_t, model_bandwidth, SCHEME_PENALTY
   use martello_links, only: LINK_SPRING, LINK_BAR, LINK_BILINEAR, L_STIFF
   use martello_contact_laws, only: LAW_LINEAR, LAW_KELVIN, P_STIFF
   use martello_status, only: MARTELLO_OK, out_of_memory, REAL_BYTES, INT_BYTES, FIX_SMALLER_SCENE
   use martello_element_rows, only: rows_t, row_lo, row_hi
   implicit none
   private
   public :: omega_max, free_dofs, mass_band


contains

   !> ω_max [rad/s]; info /= 0 if LAPACK failed (M not positive definite on the free DOFs).
   !> stat, message: as martello_status out_of_memory if the bands cannot be allocated.
   subroutine omega_max(m, w_max, info, stat, message)
      type(model_t), intent(in) :: m
      real(dp), intent(out) :: w_max
      integer, intent(out) :: info, stat
      character(len=*), intent(out) :: message
      integer :: kd, nf, j, nfound
      integer, allocatable :: dof(:), iwork(:), ifail(:)
      real(dp), allocatable :: ka(:, :), mb(:, :), w(:), work(:)
      real(dp) :: q(1, 1), z(1, 1)

      kd = max(model_bandwidth(m), 0)
      w_max = 0.0_dp; info = 0
      call free_dofs(m, dof, nf, stat, message)
      if (stat /= MARTELLO_OK .or. nf == 0) return
      ! upper band storage: A(i,j), i <= j, in ab(kd+1+i−j, j)
      allocate (ka(kd + 1, nf), w(nf), work(7*nf), iwork(5*nf), ifail(nf), stat=stat)
      if (stat /= 0) then
         call out_of_memory('the stiffness band of the stability limit', &
                            REAL_BYTES*(kd + 9.0_dp)*nf + INT_BYTES*6.0_dp*nf, FIX_SMALLER_SCENE, &
                            stat, message)
         return
      end if
      ka = 0.0_dp
      call mass_band(m, dof, nf, kd, mb, stat, message)
      if (stat /= MARTELLO_OK) return
      do j = 1, m%nlink
         select case (m%link_kind(j))
         case (LINK_SPRING, LINK_BAR, LINK_BILINEAR)
            call row(m%lnk, j, m%link_par(L_STIFF, j))
         end select
      end do
      do j = 1, m%ncontact
         if (m%con_scheme(j) /= SCHEME_PENALTY) cycle
         if (m%con_law(j) /= LAW_LINEAR .and. m%con_law(j) /= LAW_KELVIN) cycle
         call row(m%con, j, m%con_par(P_STIFF, j))
      end do
      do j = 1, m%nblock
         call block(m%block(j)%node, m%block(j)%k)
      end do
      call dsbgvx('N', 'I', 'U', nf, kd, kd, ka, kd + 1, mb, kd + 1, q, 1, 0.0_dp, 0.0_dp, &
                  nf, nf, 0.0_dp, nfound, w, z, 1, work, iwork, ifail, info)
      if (info == 0 .and. nfound >= 1) w_max = sqrt(max(w(1), 0.0_dp))

   contains
      !> ka += k gᵀg over a row's free DOFs (upper band, LAPACK's 'U' layout).
      subroutine row(rows, j, k)
         type(rows_t), intent(in) :: rows
         integer, intent(in) :: j
         real(dp), intent(in) :: k
         integer :: p, q, ip, iq
         do p = row_lo(rows, j), row_hi(rows, j)
            ip = dof(rows%node(p))
            do q = row_lo(rows, j), row_hi(rows, j)
               iq = dof(rows%node(q))
               if (ip > 0 .and. iq > 0 .and. ip <= iq) ka(kd + 1 + ip - iq, iq) = &
                  ka(kd + 1 + ip - iq, iq) + k*rows%coef(p)*rows%coef(q)
            end do
         end do
      end subroutine row
      !> a stiffness block's upper triangle on the free DOFs (fixed nodes drop out)
      subroutine block(nd, kb)
         integer, intent(in) :: nd(:)
         real(dp), intent(in) :: kb(:, :)
         integer :: p, q, ip, iq
         do q = 1, size(nd)
            do p = 1, size(nd)
               ip = dof(nd(p)); iq = dof(nd(q))
               if (ip > 0 .and. iq > 0 .and. ip <= iq) &
                  ka(kd + 1 + ip - iq, iq) = ka(kd + 1 + ip - iq, iq) + kb(p, q)
            end do
         end do
      end subroutine block
   end subroutine omega_max

   !> M (lumped diagonal plus consistent couplings) on the free nodes, dof-numbered, in
   !> LAPACK's upper band storage: M(i,j), i <= j, in mb(kd+1+i−j, j). A coupling to a fixed
   !> node drops out with that node's row and column. stat, message: as martello_status
   !> out_of_memory (absent: the process stops with its line).
   subroutine mass_band(m, dof, nf, kd, mb, stat, message)
      type(model_t), intent(in) :: m
      integer, intent(in) :: dof(0:), nf, kd
      real(dp), allocatable, intent(out) :: mb(:, :)
      integer, intent(out), optional :: stat
      character(len=*), intent(out), optional :: message
      integer :: i, j, ia, ib
      if (present(stat)) stat = MARTELLO_OK
      allocate (mb(kd + 1, nf), stat=i)
      if (i /= 0) then
         call out_of_memory('the mass band', REAL_BYTES*(kd + 1.0_dp)*nf, FIX_SMALLER_SCENE, &
                            stat, message)
         return
      end if
      mb = 0.0_dp
      do i = 1, m%n
         if (dof(i) > 0) mb(kd + 1, dof(i)) = m%mass(i)
      end do
      do j = 1, m%ncoupling
         ia = dof(m%mc_a(j)); ib = dof(m%mc_b(j))
         if (ia == 0 .or. ib == 0) cycle
         mb(kd + 1 + min(ia, ib) - max(ia, ib), max(ia, ib)) = &
            mb(kd + 1 + min(ia, ib) - max(ia, ib), max(ia, ib)) + m%mc_value(j)
      end do
   end subroutine mass_band

   !> Numbering of the free nodes: dof(i) in 1..nf, 0 for fixed nodes and ground (dof(0)).
   !> stat, message: as martello_status out_of_memory (absent: the process stops with its line).
   subroutine free_dofs(m, dof, nf, stat, message)
      type(model_t), intent(in) :: m
      integer, allocatable, intent(out) :: dof(:)
      integer, intent(out) :: nf
      integer, intent(out), optional :: stat
      character(len=*), intent(out), optional :: message
      integer :: i
      if (present(stat)) stat = MARTELLO_OK
      nf = 0
      allocate (dof(0:m%n), stat=i)
      if (i /= 0) then
         call out_of_memory('the numbering of the free nodes', INT_BYTES*(m%n + 1.0_dp), &
                            FIX_SMALLER_SCENE, stat, message)
         return
      end if
      dof = 0
      do i = 1, m%n
         if (.not. m%fixed(i)) then
            nf = nf + 1; dof(i) = nf
         end if
      end do
   end subroutine free_dofs
end module martello_stability
