!> The steps the fused chain step hands to the general path (docs/run-layer.md "The fused
!> chain step"): a step whose branches have not settled after MAX_FUSED solves, or that
!> meets a pivot ≤ 0, is taken by martello_generalized_alpha from the same committed state,
!> with its line search, chatter rule and failure messages.
submodule (martello_chain_step) general_path
   implicit none

contains

   !> A step the fused sweeps do not settle, taken by the general path from the same
   !> committed state (its chatter rule, line search and failure messages). Its stepper is
   !> made at the first such step (on the model with its chains as links and contacts one by
   !> one: their numbers are those of all the model's items) and handed the committed state
   !> each time: the element states from ours (a contact we hold open has no force), f_ext at
   !> t_n.
   module procedure general_step
      self%factored = .false.
      if (m%nchain > 0) then
         if (.not. allocated(self%gm)) then
            allocate (self%gm, stat=stat)
            if (stat /= 0) then
               call out_of_memory('a copy of the model for the general path of the fused chain step', &
                                  -1.0_dp, FIX_SMALLER_SCENE, stat, o%message)
            else
               call model_expanded(m, self%gm, stat, o%message)
            end if
            if (stat /= MARTELLO_OK) then
               call observer_failed(o, t, stat); return
            end if
            call effective_mass_prepare(self%gm, o%message, stat)
            if (stat /= MARTELLO_OK) return
         end if
         call take(self%gm)
      else
         call take(m)
      end if
   contains
      subroutine take(gm)
         type(model_t), intent(in) :: gm
         integer(i8) :: saved(size(o%counters))
         integer :: idx, j, i
         if (.not. allocated(self%gen)) then
            ! its start at t = 0 (a = M⁻¹(f_ext − f_int)) is overwritten below: not counted
            allocate (self%gen, stat=stat)
            if (stat /= 0) then
               call out_of_memory('the general path of the fused chain step', -1.0_dp, &
                                  FIX_SMALLER_SCENE, stat, o%message)
               call observer_failed(o, t, stat); return
            end if
            saved = o%counters
            call self%gen%init(gm, self%settings, o, stat)
            o%counters = saved
            if (stat /= MARTELLO_OK) return
         end if
         associate (gen => self%gen, ms => self%gen%ms)
            associate (x => self%store, n => self%n)
               gen%un = x(self%oun:self%oun + n); gen%vn = x(self%ovn:self%ovn + n)
               gen%an = x(self%oan:self%oan + n)
            end associate
            gen%t0 = self%t0
            do idx = 1, size(self%blk%blo)
               j = self%blk%blo(idx)
               ms%link_fc(j) = self%bfc(idx); ms%link_u(j) = self%bdu(idx)
            end do
            ms%forced_off = .false.
            call internal_forces(gm, ms, gen%un, gen%vn, gen%fint)
            call mech_commit(gm, ms, gen%un)
            do i = 1, m%n - 1
               if (self%pair_contact(i) > 0) call hold(self%pair_contact(i), self%pbrc(i))
            end do
            do idx = 1, size(self%blk%xc)
               call hold(self%blk%xc(idx), self%xbrc(idx))
            end do
            call external_forces(gm, gen%mrow, self%t0, gen%fext)
            gen%tangent_valid = .false.
            call gen%step(gm, t, o, stat)
            if (stat /= MARTELLO_OK) return
            associate (x => self%store, n => self%n)
               x(self%ou:self%ou + n) = gen%u; x(self%ov:self%ov + n) = gen%v
               x(self%oa:self%oa + n) = gen%a
            end associate
            do idx = 1, size(self%blk%blo)
               j = self%blk%blo(idx)
               self%bfc(idx) = ms%link_fc(j); self%bdu(idx) = ms%link_u(j)
            end do
            do i = 1, m%n - 1
               if (self%pair_contact(i) > 0) self%pbrc(i) = branch_of(self%pair_contact(i))
            end do
            do idx = 1, size(self%blk%xc)
               self%xbrc(idx) = branch_of(self%blk%xc(idx))
            end do
         end associate
      end subroutine take

      !> contact j committed off here is off there (no force)
      subroutine hold(j, br)
         integer, intent(in) :: j
         integer(int8), intent(in) :: br
         if (br /= BRANCH_OFF) return
         self%gen%ms%con_on(j) = .false.; self%gen%ms%con_f(j) = 0.0_dp
      end subroutine hold

      !> our branch of contact j from the general path's committed state: clipped where the
      !> Kelvin law's cut-off holds its force at 0
      integer(int8) function branch_of(j) result(br)
         integer, intent(in) :: j
         integer :: a, b, scheme, law
         real(dp) :: gap, par(NPAR_CONTACT)
         br = BRANCH_OFF
         if (.not. self%gen%ms%con_on(j)) return
         br = BRANCH_ON
         call model_contact_at(m, j, a, b, gap, scheme, law, par)
         if (law == LAW_KELVIN .and. par(P_CLIP) > 0.5_dp .and. self%gen%ms%con_f(j) == 0.0_dp) &
            br = BRANCH_CLIPPED
      end function branch_of
   end procedure general_step
end submodule general_path
