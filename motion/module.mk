# motion/: segment queue, velocity planner, servo-period interpolator, and its HAL component.
