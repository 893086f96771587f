! usr_drag_draglab.f: MFiX's user drag hook evaluating a stored draglab law.
!
! MFiX calls DRAG_USR (argument list of MFiX 2015-1 and later, model/usr_drag.f) from DRAG_GS for
! every fluid cell and solids phase (TFM), and from the DES drag for every particle, when the
! project sets DRAG_TYPE = 'USER_DRAG'. Copy this file over the project's usr_drag.f (free-form
! source, as MFiX compiles it) and link the draglab Fortran module:
!   FCFLAGS += $(pkg-config --cflags draglab-fortran)   LIBS += $(pkg-config --libs draglab-fortran)
!
! The law is chosen at run time, on the first call, by the environment:
!   DRAGLAB_LAW           name@version, as `draglab law list` shows (required)
!   DRAGLAB_DB            the database (default: ./draglab.db)
!   DRAGLAB_RANGE_POLICY  error (default), clamp or extrapolate: inputs outside the law's box
!
! Output: lDgA = beta / eps_s = 18 mu_g eps_g F / d_p^2 [kg m^-3 s^-1], the law's friction
! coefficient per unit solids fraction, with F evaluated at phi = 1 - EPg and the superficial
! Re = EPg ROg VREL DPM / Mug (VREL the interstitial slip). MFiX scales it itself in DRAG_GS:
! F_gs = lDgA * EP_s for model A (= beta) and lDgA * EP_s / EPg for model B (= beta / eps_g), so
! one lDgA serves both, as for MFiX's own laws. Every failure (no DRAGLAB_LAW, an unknown law,
! inputs outside the box with policy error) stops the run through MFiX's error manager, naming
! the law, the cell and the inputs; no NaN is ever returned.
!
! Not thread-safe on its first call (the law is loaded once, then shared read-only); MFiX's drag
! loops call it from one thread.
      SUBROUTINE DRAG_USR(IJK, M_NP, lDgA, EPg, Mug, ROg, VREL, DPM, &
         ROs, lUg, lVg, lWg)

      use, intrinsic :: iso_c_binding, only: c_double, c_int
      use draglab_mod
      use error_manager

      IMPLICIT NONE

! Index of fluid cell:
      INTEGER, INTENT(IN) :: IJK
! TFM: index of the solids phase; DES: index of the particle
      INTEGER, INTENT(IN) :: M_NP
! drag coefficient per unit solids fraction (see above)
      DOUBLE PRECISION, INTENT(OUT) :: lDgA
! gas volume fraction, gas viscosity [Pa s], gas density [kg/m^3]
      DOUBLE PRECISION, INTENT(IN) :: EPg, Mug, ROg
! magnitude of the gas-solids relative velocity [m/s]
      DOUBLE PRECISION, INTENT(IN) :: VREL
! particle diameter [m] and density [kg/m^3]
      DOUBLE PRECISION, INTENT(IN) :: DPM, ROs
! gas velocity at the particle (DES) or cell centre (TFM): unused
      DOUBLE PRECISION, INTENT(IN) :: lUg, lVg, lWg

      type(draglab_db_t), save :: db
      type(draglab_law_t), save :: law
      logical, save :: loaded = .false.
      integer(c_int) :: status
      real(c_double) :: value
      character(len=512) :: where

      IF (.NOT. loaded) CALL LOAD_LAW()

      status = draglab_law_dga(law, real(EPg, c_double), real(Mug, c_double), &
         real(ROg, c_double), real(VREL, c_double), real(DPM, c_double), &
         real(ROs, c_double), value)
      IF (status /= DRAGLAB_OK) THEN
         WRITE(where, "('at fluid cell ',I0,', phase or particle ',I0,': EPg = ',G0.8, &
            &', Mug = ',G0.8,', ROg = ',G0.8,', VREL = ',G0.8,', DPM = ',G0.8)") &
            IJK, M_NP, EPg, Mug, ROg, VREL, DPM
         CALL REPORT(TRIM(draglab_last_error()) // ' ' // TRIM(where))
         lDgA = 0.0D0
         RETURN
      ENDIF
      lDgA = value
      RETURN

      CONTAINS

      SUBROUTINE LOAD_LAW()
      character(len=1024) :: ref, path, policy_name
      integer :: length, got
      integer(c_int) :: policy

      CALL GET_ENVIRONMENT_VARIABLE('DRAGLAB_LAW', ref, length, got)
      IF (got /= 0 .OR. length == 0) THEN
         CALL REPORT('set DRAGLAB_LAW to the law to use (name@version, as `draglab law ' // &
            'list` shows) for DRAG_TYPE = USER_DRAG')
         RETURN
      ENDIF
      CALL GET_ENVIRONMENT_VARIABLE('DRAGLAB_DB', path, length, got)
      IF (got /= 0 .OR. length == 0) path = 'draglab.db'
      IF (draglab_db_open_readonly(TRIM(path), db) /= DRAGLAB_OK) THEN
         CALL REPORT('cannot open the database ' // TRIM(path) // ': ' // &
            TRIM(draglab_last_error()))
         RETURN
      ENDIF
      IF (draglab_law_load(db, TRIM(ref), law) /= DRAGLAB_OK) THEN
         CALL REPORT('cannot load the law ' // TRIM(ref) // ' from ' // TRIM(path) // ': ' // &
            TRIM(draglab_last_error()))
         RETURN
      ENDIF
      policy = DRAGLAB_RANGE_ERROR
      CALL GET_ENVIRONMENT_VARIABLE('DRAGLAB_RANGE_POLICY', policy_name, length, got)
      IF (got == 0 .AND. length > 0) THEN
         SELECT CASE (TRIM(policy_name))
         CASE ('error')
            policy = DRAGLAB_RANGE_ERROR
         CASE ('clamp')
            policy = DRAGLAB_RANGE_CLAMP
         CASE ('extrapolate')
            policy = DRAGLAB_RANGE_EXTRAPOLATE
         CASE DEFAULT
            CALL REPORT('DRAGLAB_RANGE_POLICY = ' // TRIM(policy_name) // &
               ' is not one of error, clamp, extrapolate')
            RETURN
         END SELECT
      ENDIF
      status = draglab_law_set_range_policy(law, policy)
      loaded = .true.
      END SUBROUTINE LOAD_LAW

! Stops the run through MFiX's error manager with `text`, in lines of at most 200 characters.
      SUBROUTINE REPORT(text)
      character(len=*), intent(in) :: text
      character(len=:), allocatable :: full
      integer :: line, first
      full = 'draglab: ' // text
      CALL INIT_ERR_MSG('USR_DRAG (draglab)')
      line = 0
      first = 1
      DO WHILE (first <= LEN(full) .AND. line < SIZE(ERR_MSG))
         line = line + 1
         ERR_MSG(line) = full(first:MIN(LEN(full), first + 199))
         first = first + 200
      ENDDO
      CALL FLUSH_ERR_MSG(ABORT=.TRUE.)
      END SUBROUTINE REPORT

      END SUBROUTINE DRAG_USR
