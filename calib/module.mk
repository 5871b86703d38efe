# calib/: kinematic calibration (docs/calibration.md): the fit with Ceres, the pose plan,
# and `make calibration`, the simulated experiment on a perturbed TMU machine.
LIB_SRCS += calib/calib_csv.c calib/calib_fit.c calib/calib_kins.c calib/calib_plan.c
LIB_CXXSRCS += calib/calib_solve.cpp
TESTS += test_calibrate
