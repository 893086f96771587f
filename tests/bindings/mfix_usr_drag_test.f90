! MFiX's DRAG_USR hook (adapters/mfix/usr_drag_draglab.f) called as MFiX calls it, outside MFiX.
!
! Set-up: error_manager below stands in for MFiX's module of that name (the same ERR_MSG lines,
! INIT_ERR_MSG and FLUSH_ERR_MSG; an abort stops with exit code 3). The program calls DRAG_USR
! with MFiX-style arguments (SI units: EPg, Mug, ROg, VREL, DPM, ROs) over dense and dilute
! cells, slow and fast slip, with DRAGLAB_LAW = gidaspow@1 (set by ctest), and checks:
!  1. lDgA equals the C ABI's draglab_law_dga for the same law (the shim adds nothing);
!  2. MFiX's model-A and model-B coefficients built from it as DRAG_GS does (lDgA EP_s and
!     lDgA EP_s / EPg) equal the law's beta and beta / EPg (draglab_law_beta): 1e-13 relative,
!     a few roundings;
!  3. lDgA equals MFiX's own DRAG_GIDASPOW (Gidaspow 1994 as MFiX implements it in
!     model/drag_gs.f: Ergun for EPg <= 0.8, Wen-Yu above with the Schiller-Naumann C_d and
!     ROPg = EPg ROg), written out here as the reference: 1e-12 relative (the same formula in
!     another order of operations).
! With argument "outside", one call at EPg = 0.3 (phi = 0.7, above gidaspow's box) must stop
! through the error manager naming the cell (ctest checks the message).
! Usage: mfix_usr_drag_test DATABASE [outside]
module error_manager
  implicit none
  integer, parameter :: LINE_COUNT = 32, LINE_LENGTH = 256
  character(len=LINE_LENGTH), dimension(LINE_COUNT) :: ERR_MSG
  character(len=128), private :: caller = ''
contains
  subroutine init_err_msg(name)
    character(len=*), intent(in) :: name
    caller = name
    ERR_MSG = ''
  end subroutine init_err_msg
  subroutine flush_err_msg(abort)
    logical, intent(in), optional :: abort
    integer :: i
    write (*, '(A)') 'ERROR from ' // trim(caller) // ':'
    do i = 1, LINE_COUNT
      if (len_trim(ERR_MSG(i)) > 0) write (*, '(A)') trim(ERR_MSG(i))
    end do
    if (present(abort)) then
      if (abort) error stop 3
    end if
  end subroutine flush_err_msg
end module error_manager

program mfix_usr_drag_test
  use, intrinsic :: iso_c_binding, only: c_double
  use draglab_mod
  implicit none
  interface
    subroutine DRAG_USR(IJK, M_NP, lDgA, EPg, Mug, ROg, VREL, DPM, ROs, lUg, lVg, lWg)
      integer, intent(in) :: IJK, M_NP
      double precision, intent(out) :: lDgA
      double precision, intent(in) :: EPg, Mug, ROg, VREL, DPM, ROs, lUg, lVg, lWg
    end subroutine DRAG_USR
  end interface
  double precision, parameter :: mug = 1.8d-5, rog = 1.2d0, dpm = 5.0d-4, ros = 2500.0d0
  double precision, parameter :: epgs(7) = [0.36d0, 0.45d0, 0.6d0, 0.79d0, 0.81d0, 0.9d0, 0.99d0]
  double precision, parameter :: vrels(4) = [1.0d-3, 0.05d0, 0.5d0, 3.0d0]
  character(len=1024) :: path, mode
  type(draglab_db_t) :: db
  type(draglab_law_t) :: law
  double precision :: lDgA, dga, beta, eps_s, reference, worst_abi, worst_ab, worst_mfix
  integer :: i, j, cell, failures

  call get_command_argument(1, path)
  call get_command_argument(2, mode)
  ! Create and seed the database the shim opens read-only.
  if (draglab_db_open(trim(path), db) /= DRAGLAB_OK) error stop 'cannot create the database'
  if (draglab_law_load(db, 'gidaspow@1', law) /= DRAGLAB_OK) error stop 'cannot load gidaspow@1'

  if (trim(mode) == 'outside') then
    call DRAG_USR(42, 1, lDgA, 0.3d0, mug, rog, 0.5d0, dpm, ros, 0d0, 0d0, 0d0)
    print *, 'no error for EPg = 0.3: ', lDgA
    error stop 1
  end if

  worst_abi = 0; worst_ab = 0; worst_mfix = 0; cell = 0
  do i = 1, size(epgs)
    do j = 1, size(vrels)
      cell = cell + 1
      call DRAG_USR(cell, 1, lDgA, epgs(i), mug, rog, vrels(j), dpm, ros, 0d0, 0d0, 0d0)
      if (draglab_law_dga(law, epgs(i), mug, rog, vrels(j), dpm, ros, dga) /= DRAGLAB_OK) &
        error stop 'draglab_law_dga failed'
      if (draglab_law_beta(law, epgs(i), mug, rog, vrels(j), dpm, ros, beta) /= DRAGLAB_OK) &
        error stop 'draglab_law_beta failed'
      eps_s = 1.0d0 - epgs(i)
      worst_abi = max(worst_abi, abs(lDgA / dga - 1.0d0))
      worst_ab = max(worst_ab, abs(lDgA * eps_s / beta - 1.0d0), &
                     abs((lDgA * eps_s / epgs(i)) / (beta / epgs(i)) - 1.0d0))
      reference = mfix_gidaspow(epgs(i), vrels(j))
      worst_mfix = max(worst_mfix, abs(lDgA / reference - 1.0d0))
    end do
  end do
  print '(A,ES10.3)', 'lDgA against draglab_law_dga:             ', worst_abi
  print '(A,ES10.3)', 'model A/B coefficients against beta:      ', worst_ab
  print '(A,ES10.3)', 'lDgA against MFiX''s DRAG_GIDASPOW formula: ', worst_mfix
  failures = 0
  if (worst_abi > 1.0d-15) failures = failures + 1
  if (worst_ab > 1.0d-13) failures = failures + 1
  if (worst_mfix > 1.0d-12) failures = failures + 1
  call draglab_law_free(law)
  call draglab_db_close(db)
  if (failures > 0) error stop 1
  print '(A,I0,A)', 'all ', cell, ' cells agree'

contains

  ! MFiX's DRAG_GIDASPOW (model/drag_gs.f), the published Gidaspow (1994) law in MFiX's form.
  double precision function mfix_gidaspow(epg, vrel) result(dga_mfix)
    double precision, intent(in) :: epg, vrel
    double precision :: re, cd, ropg
    ropg = epg * rog
    re = dpm * vrel * ropg / mug
    if (epg <= 0.8d0) then
      dga_mfix = 150.0d0 * (1.0d0 - epg) * mug / (epg * dpm**2) + 1.75d0 * rog * vrel / dpm
    else
      if (re <= 1000.0d0) then
        cd = 24.0d0 / re * (1.0d0 + 0.15d0 * re**0.687d0)
      else
        cd = 0.44d0
      end if
      dga_mfix = 0.75d0 * cd * vrel * ropg * epg**(-2.65d0) / dpm
    end if
  end function mfix_gidaspow
end program mfix_usr_drag_test
