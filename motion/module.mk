# motion/: segment queue, velocity planner, servo-period interpolator, and its HAL component.
LIB_SRCS += motion/motion.c motion/motion_config.c motion/motion_path.c motion/motion_plan.c \
            motion/motion_caps.c motion/motion_blend.c motion/motion_chord.c \
            motion/motion_step.c motion/motion_rate.c motion/motion_manual.c motion/motion_home.c \
            motion/motion_stream.c motion/motion_merge.c motion/motion_probe.c \
            motion/motion_jerk.c motion/motion_sync.c motion/motion_ahead.c motion/motion_hold.c
TESTS += test_motion test_motion_run test_motion_legs test_motion_override test_motion_hal \
         test_motion_blend test_motion_chords \
         test_motion_stop test_motion_manual test_motion_spindle test_motion_stream test_motion_merge \
         test_motion_small_arcs test_motion_probe test_motion_jerk test_motion_sync \
         test_motion_random
# The HAL component `motion` (loadrt motion) and the runner's entry points (motion_hal.h).
LIB_SRCS += hal/components/motion.c
HAL_COMPS += motion
BENCHES += bench_motion bench_topp bench_topp_blend bench_jerk
