/* config_keys.c: every INI section and key hexcnc reads, with type, unit, range, default and
 * meaning: the one place to add a key (grouped per section, one line per key). The whole-file
 * check (config_check.c) and docs/ini.md (`make ini-doc`) are made from it.
 *
 * Columns: section, key, type, unit, range (numbers: "", "> A", ">= A", "A..B", "!= 0";
 * enums: the words "a|b"), count (NUMBERS), flags, default ("" = none), meaning.
 * '#' in a section or key name stands for an index: JOINT_# is JOINT_0, JOINT_1, ...; a
 * final '*' for any ending (AXIS_* is AXIS_X, AXIS_Y, ...). */
#include "common/config.h"

#define NUM CONFIG_NUMBER
#define NUMS CONFIG_NUMBERS
#define INT CONFIG_INTEGER
#define BOOL CONFIG_BOOL
#define STR CONFIG_STRING
#define PATH CONFIG_PATH
#define ENUM CONFIG_ENUM
#define REQ CONFIG_REQUIRED
#define REP CONFIG_REPEAT
#define IGN CONFIG_IGNORED

const struct config_section config_sections[] = {
    { "EMC", CONFIG_OPEN, "LinuxCNC's machine description; hexcnc reads none of it" },
    { "KINS", CONFIG_STRICT, "kinematics model and hexapod geometry (docs/kinematics.md)" },
    { "TRAJ", CONFIG_STRICT, "path limits and the kinematic-error bound (docs/motion.md)" },
    { "EMCMOT", CONFIG_STRICT, "servo period and clock" },
    { "JOINT_#", CONFIG_STRICT, "one leg: length limits, speed limits, following error, "
      "step generator" },
    { "RS274NGC", CONFIG_STRICT, "interpreter settings (docs/gcode.md)" },
    { "PROBE", CONFIG_STRICT, "the workpiece G38 probing touches in `hexcnc interp -i` and "
      "`hexcnc check` (docs/gcode.md)" },
    { "SPINDLE_SYNC", CONFIG_STRICT, "the spindle as G33 and G33.1 follow it (docs/gcode.md)" },
    { "EMCIO", CONFIG_OPEN, "LinuxCNC's I/O controller; hexcnc reads TOOL_TABLE only" },
    { "HAL", CONFIG_STRICT, "HAL files run when the machine starts (docs/hal.md)" },
    { "TASK", CONFIG_STRICT, "`hexcnc run` (docs/running.md)" },
    { "API", CONFIG_STRICT, "the machine session's command socket (docs/api.md)" },
    { "DISPLAY", CONFIG_OPEN, "LinuxCNC's GUI settings; hexcnc reads OPEN_FILE only" },
    { "LCM", CONFIG_STRICT, "status publishing over LCM (docs/lcm.md)" },
    { "MODBUS", CONFIG_STRICT, "Modbus drives, settings common to all (docs/modbus.md)" },
    { "MODBUS_DRIVE_#", CONFIG_STRICT, "one Modbus drive: any [MODBUS] key except DRIVES, "
      "for this drive only" },
    { "MODBUS_SIM", CONFIG_STRICT, "the simulated Modbus drives" },
    { "CAN", CONFIG_STRICT, "CANopen bus and CiA 402 master (docs/can.md)" },
    { "CAN_NODE_#", CONFIG_STRICT, "one CiA 402 drive, joint #" },
    { "AXIS_X", CONFIG_STRICT, "the pose's X in machine coordinates: soft limits; "
      "LinuxCNC's axis speeds here are accepted and ignored" },
    { "AXIS_Y", CONFIG_STRICT, "the pose's Y in machine coordinates: soft limits; "
      "LinuxCNC's axis speeds here are accepted and ignored" },
    { "AXIS_Z", CONFIG_STRICT, "the pose's Z in machine coordinates: soft limits; "
      "LinuxCNC's axis speeds here are accepted and ignored" },
    { "AXIS_A", CONFIG_STRICT, "the pose's A in machine coordinates: soft limits; "
      "LinuxCNC's axis speeds here are accepted and ignored" },
    { "AXIS_B", CONFIG_STRICT, "the pose's B in machine coordinates: soft limits; "
      "LinuxCNC's axis speeds here are accepted and ignored" },
    { "AXIS_C", CONFIG_STRICT, "the pose's C in machine coordinates: soft limits; "
      "LinuxCNC's axis speeds here are accepted and ignored" },
    /* Other programs' sections, accepted and ignored so a LinuxCNC INI can be used. */
    { "HALUI", CONFIG_FOREIGN, "LinuxCNC's halui" },
    { "FILTER", CONFIG_FOREIGN, "LinuxCNC's program filters" },
    { "AXIS_*", CONFIG_FOREIGN, "LinuxCNC's per-axis limits (hexcnc limits legs, [JOINT_#], "
      "and the path, [TRAJ])" },
    { "SPINDLE_#", CONFIG_FOREIGN, "LinuxCNC's spindle settings" },
    { "PYTHON", CONFIG_FOREIGN, "LinuxCNC's Python plugins" },
    { "TOOLSENSOR", CONFIG_FOREIGN, "LinuxCNC GUIs' tool sensor" },
};
const int config_nsections = sizeof config_sections / sizeof config_sections[0];

const struct config_key config_keys[] = {
    /* [EMC]: LinuxCNC's, documented here because hexcnc's own INIs carry them. */
    { "EMC", "MACHINE", STR, "", "", 0, IGN, "", "machine name shown by LinuxCNC GUIs" },
    { "EMC", "VERSION", STR, "", "", 0, IGN, "", "INI format version (LinuxCNC)" },

    /* [KINS] */
    { "KINS", "KINEMATICS", STR, "", "", 0, REQ, "", "kinematics model: hexapod or trivial "
      "(a plugin lib/kins/NAME.so)" },
    { "KINS", "JOINTS", INT, "", "1..9", 0, 0, "6", "number of joints (legs)" },
    { "KINS", "BASE_RADIUS", NUM, "mm", "0.001..1e6", 0, 0, "", "hexapod: radius of the base "
      "joint circle (required unless BASE_#/PLATFORM_# are given)" },
    { "KINS", "PLATFORM_RADIUS", NUM, "mm", "0..1e6", 0, 0, "", "hexapod: radius of the "
      "platform joint circle (required unless BASE_#/PLATFORM_# are given)" },
    { "KINS", "BASE_HALF_ANGLE", NUM, "deg", "0..59", 0, 0, "", "hexapod: half the angle "
      "between the two base joints of a pair (required with BASE_RADIUS)" },
    { "KINS", "PLATFORM_HALF_ANGLE", NUM, "deg", "0..59", 0, 0, "", "hexapod: half the angle "
      "between the two platform joints of a pair (required with PLATFORM_RADIUS)" },
    { "KINS", "BASE_Z", NUM, "mm", "", 0, 0, "0", "hexapod: height of the base joint centres" },
    { "KINS", "PLATFORM_Z", NUM, "mm", "", 0, 0, "0", "hexapod: height of the platform joint "
      "centres in the platform frame" },
    { "KINS", "BASE_#", NUMS, "mm", "", 3, 0, "", "hexapod: base joint # (0..5) as x y z, "
      "instead of the radius and angle keys" },
    { "KINS", "PLATFORM_#", NUMS, "mm", "", 3, 0, "", "hexapod: platform joint # (0..5) as "
      "x y z in the platform frame" },
    { "KINS", "LEG_OFFSET", NUMS, "mm", "-1000..1000", 6, 0, "0 0 0 0 0 0", "hexapod: per leg, "
      "joint-centre distance minus the length the drive reports (calibration)" },
    { "KINS", "HOME", NUMS, "mm, deg", "", 6, 0, "level, legs mid-range", "pose X Y Z A B C "
      "the forward solver starts from" },
    { "KINS", "PLATFORM_CARRIES", ENUM, "", "WORKPIECE|SPINDLE", 0, 0, "WORKPIECE", "what "
      "the hexapod's platform carries" },
    { "KINS", "TOOL_POINT", NUMS, "mm", "", 3, 0, "HOME's X Y Z", "spindle gauge point, in "
      "the frame the spindle is fixed to" },
    { "KINS", "TOOL_AXIS", NUMS, "", "", 3, 0, "0 0 -1", "direction the tool points (any "
      "length but zero)" },
    { "KINS", "TOOL_LENGTH", NUM, "mm", "", 0, 0, "0", "tool tip beyond TOOL_POINT along "
      "TOOL_AXIS" },
    { "KINS", "PROGRAM_POINT", ENUM, "", "PLATFORM|TOOL_TIP", 0, 0, "PLATFORM", "what "
      "a program's X Y Z A B C command: the platform's pose, or the tool tip and orientation "
      "(tool centre point control, as under G43.4)" },
    { "KINS", "FWD_TOLERANCE", NUM, "mm", "1e-15..1", 0, 0, "1e-9", "forward solve stops "
      "below this Newton step" },
    { "KINS", "FWD_MAX_ITERATIONS", INT, "", "1..1000", 0, 0, "20", "forward solve iteration "
      "limit" },
    { "KINS", "SINGULAR_CONDITION", NUM, "", "1..1e15", 0, 0, "100", "Jacobian condition "
      "number above which a pose counts as near-singular" },
    { "KINS", "BASE_JOINT_MAX_ANGLE", NUM, "deg", "(0..89.9]", 0, 0, "", "largest angle "
      "between a leg and its base joint's axis (the base normal); absent: not limited" },
    { "KINS", "BASE_JOINT_AXIS", NUMS, "", "", 3, 0, "0 0 1", "mounting axis of every "
      "base joint, base frame, pointing up along the legs (needs BASE_JOINT_MAX_ANGLE)" },
    { "KINS", "BASE_JOINT_AXIS_#", NUMS, "", "", 3, 0, "BASE_JOINT_AXIS", "mounting axis of "
      "base joint # (0..5), in place of BASE_JOINT_AXIS" },
    { "KINS", "PLATFORM_JOINT_AXIS", NUMS, "", "", 3, 0, "0 0 1", "mounting axis of every "
      "platform joint, platform frame, pointing up (needs PLATFORM_JOINT_MAX_ANGLE)" },
    { "KINS", "PLATFORM_JOINT_AXIS_#", NUMS, "", "", 3, 0, "PLATFORM_JOINT_AXIS", "mounting "
      "axis of platform joint # (0..5), in place of PLATFORM_JOINT_AXIS" },
    { "KINS", "PLATFORM_JOINT_MAX_ANGLE", NUM, "deg", "(0..89.9]", 0, 0, "", "largest angle "
      "between a leg and its platform joint's axis (PLATFORM_JOINT_AXIS); absent: not "
      "limited" },
    { "KINS", "LEG_DIAMETER", NUM, "mm", "(0..1000]", 0, 0, "", "legs' outer diameter: two "
      "legs' axes stay LEG_DIAMETER + LEG_CLEARANCE apart; absent: not checked" },
    { "KINS", "LEG_CLEARANCE", NUM, "mm", "0..1000", 0, 0, "0", "gap kept between two legs' "
      "surfaces (needs LEG_DIAMETER)" },
    { "KINS", "CHARACTERISTIC_LENGTH", NUM, "mm", "0.001..1e6", 0, 0, "platform joint "
      "radius", "lever arm that scales rotations against lengths in the condition number" },

    /* [TRAJ] */
    { "TRAJ", "MAX_LINEAR_VELOCITY", NUM, "mm/s", "> 0", 0, REQ, "", "path speed limit, X Y "
      "Z (also the rapid rate)" },
    { "TRAJ", "MAX_LINEAR_ACCELERATION", NUM, "mm/s^2", "> 0", 0, REQ, "", "path "
      "acceleration limit, X Y Z" },
    { "TRAJ", "MAX_ANGULAR_VELOCITY", NUM, "deg/s", "> 0", 0, REQ, "", "speed limit of each "
      "of A B C" },
    { "TRAJ", "MAX_ANGULAR_ACCELERATION", NUM, "deg/s^2", "> 0", 0, REQ, "", "acceleration "
      "limit of each of A B C" },
    { "TRAJ", "DEFAULT_LINEAR_VELOCITY", NUM, "mm/s", "> 0", 0, 0, "10", "feed of a move "
      "programmed before any F word" },
    { "TRAJ", "KINEMATIC_TOLERANCE", NUM, "mm", ">= 0", 0, 0, "0.001", "largest distance of "
      "the tool from the programmed line between set points" },
    { "TRAJ", "KINEMATIC_ANGULAR_TOLERANCE", NUM, "deg", ">= 0", 0, 0, "0.001", "the same "
      "bound for the orientation" },
    { "TRAJ", "BLEND_TOLERANCE", NUM, "mm", ">= 0", 0, 0, "0.01", "G64 without P: largest "
      "corner cut when blending" },
    { "TRAJ", "SETPOINT_PERIOD", INT, "ns", ">= 0", 0, 0, "servo period", "period at which "
      "drives take set points, for the kinematic-error bound" },
    { "TRAJ", "MAX_LINEAR_JERK", NUM, "mm/s^3", "> 0", 0, 0, "none (trapezoidal)", "path "
      "jerk limit, X Y Z: with MAX_ANGULAR_JERK and every [JOINT_#] MAX_JERK, motion is "
      "jerk-limited (docs/motion.md); all or none" },
    { "TRAJ", "MAX_ANGULAR_JERK", NUM, "deg/s^3", "> 0", 0, 0, "none (trapezoidal)", "jerk "
      "limit of each of A B C; all or none, with MAX_LINEAR_JERK" },
    { "TRAJ", "JERK_WINDOW", NUM, "s", "> 0", 0, 0, "the path's 2 x acceleration / jerk",
      "the jerk limits' moving average, up to the longest 2 x acceleration / jerk (every "
      "acceleration in full); where shorter, each acceleration is lowered to jerk x window / "
      "2: dense blended code runs faster, ramps slower. The default is the path's and A B C's "
      "2 x acceleration / jerk, and a leg's with its acceleration taken no higher than "
      "MAX_LINEAR_ACCELERATION; no shorter than 20 ms, or the full window where that is "
      "shorter (docs/motion.md)" },
    { "TRAJ", "NO_FORCE_HOMING", BOOL, "", "", 0, 0, "0", "1: programs and MDI may run "
      "before the legs are homed (the session, docs/machine.md)" },
    { "TRAJ", "OPTIONAL_STOP", BOOL, "", "", 0, 0, "1", "M1 stops the program" },
    { "TRAJ", "COORDINATES", STR, "", "", 0, IGN, "", "LinuxCNC's axis letters; hexcnc's are "
      "always X Y Z A B C" },
    { "TRAJ", "LINEAR_UNITS", ENUM, "", "mm|metric", 0, 0, "mm", "machine length unit: "
      "hexcnc machines are metric" },
    { "TRAJ", "ANGULAR_UNITS", ENUM, "", "degree|deg", 0, 0, "degree", "machine angle unit" },

    /* [EMCMOT] */
    { "EMCMOT", "SERVO_PERIOD", INT, "ns", "1000..1e9", 0, 0, "1000000", "servo thread "
      "period" },
    { "EMCMOT", "SIM_CLOCK", INT, "", "0..1", 0, 0, "0", "`hexcnc run` runs on the simulated "
      "clock (1) or paces the servo thread on the wall clock (0)" },
    { "EMCMOT", "NUM_DIO", INT, "", "0..64", 0, 0, "4", "digital outputs "
      "motion.digital-out-NN (M62..M65) and inputs motion.digital-in-NN (M66 P)" },
    { "EMCMOT", "NUM_AIO", INT, "", "0..16", 0, 0, "4", "analog outputs "
      "motion.analog-out-NN (M67, M68) and inputs motion.analog-in-NN (M66 E)" },
    { "EMCMOT", "EMCMOT", STR, "", "", 0, IGN, "", "LinuxCNC's motion module" },
    { "EMCMOT", "COMM_TIMEOUT", NUM, "s", "", 0, IGN, "", "LinuxCNC's" },
    { "EMCMOT", "BASE_PERIOD", INT, "ns", "", 0, IGN, "", "LinuxCNC's base thread" },

    /* [JOINT_#]: the limits that protect the machine have no default. */
    { "JOINT_#", "MIN_LIMIT", NUM, "mm", "", 0, REQ, "", "shortest leg length" },
    { "JOINT_#", "MAX_LIMIT", NUM, "mm", "", 0, REQ, "", "longest leg length" },
    { "JOINT_#", "MAX_VELOCITY", NUM, "mm/s", "> 0", 0, REQ, "", "leg speed limit" },
    { "JOINT_#", "MAX_ACCELERATION", NUM, "mm/s^2", "> 0", 0, REQ, "", "leg acceleration "
      "limit" },
    { "JOINT_#", "MAX_JERK", NUM, "mm/s^3", "> 0", 0, 0, "none (trapezoidal)", "leg jerk "
      "limit; all or none, with [TRAJ] MAX_LINEAR_JERK" },
    { "JOINT_#", "FERROR", NUM, "mm", "> 0", 0, REQ, "", "following-error limit at "
      "MAX_VELOCITY" },
    { "JOINT_#", "MIN_FERROR", NUM, "mm", "> 0", 0, 0, "0.1", "following-error limit at "
      "standstill (it grows with speed up to FERROR)" },
    { "JOINT_#", "SCALE", NUM, "steps/mm", "!= 0", 0, 0, "", "step generator scale (HAL "
      "files, `hexcnc check`)" },
    { "JOINT_#", "STEPGEN_MAXVEL", NUM, "mm/s", ">= 0", 0, 0, "", "step generator speed "
      "limit (0 or absent: none)" },
    { "JOINT_#", "STEPGEN_MAXACCEL", NUM, "mm/s^2", ">= 0", 0, 0, "", "step generator "
      "acceleration limit (0 or absent: none)" },
    { "JOINT_#", "HOME_SEARCH_VEL", NUM, "mm/s", "", 0, 0, "0", "homing: speed towards the "
      "home switch, its sign the direction; 0 = no switch: the leg's feedback is absolute "
      "(docs/machine.md)" },
    { "JOINT_#", "HOME_LATCH_VEL", NUM, "mm/s", "!= 0", 0, 0, "", "homing: speed of the "
      "slow, precise pass over the switch (same sign as the search: approach again; "
      "opposite: latch where it releases); required with HOME_SEARCH_VEL" },
    { "JOINT_#", "HOME_FINAL_VEL", NUM, "mm/s", "> 0", 0, 0, "MAX_VELOCITY", "homing: speed "
      "of the move to HOME after the latch" },
    { "JOINT_#", "HOME_OFFSET", NUM, "mm", "", 0, 0, "", "homing: the leg's length where the "
      "switch latches; required with HOME_SEARCH_VEL" },
    { "JOINT_#", "HOME", NUM, "mm", "", 0, 0, "leg length at [KINS] HOME", "homing: the leg "
      "length the leg moves to after the latch" },
    { "JOINT_#", "HOME_SEQUENCE", INT, "", "-9..9", 0, 0, "0", "homing: legs home in groups "
      "of equal |HOME_SEQUENCE|, lowest first; the legs of a group move together" },
    { "JOINT_#", "HOME_IGNORE_LIMITS", BOOL, "", "", 0, 0, "0", "homing: the switch shares "
      "the limit switch (hexcnc checks no limit switch while homing either way)" },
    { "JOINT_#", "HOME_ABSOLUTE_ENCODER", INT, "", "0..2", 0, 0, "0", "homing without "
      "motion: the feedback is absolute (1, 2: as LinuxCNC; both leave the platform where "
      "it is)" },
    { "JOINT_#", "HOME_SEARCH_DISTANCE", NUM, "mm", "> 0", 0, 0, "1.5 x leg range", "homing: "
      "travel without finding the switch after which homing stops with a fault" },
    { "JOINT_#", "HOME_USE_INDEX", BOOL, "", "", 0, IGN, "", "LinuxCNC's encoder index "
      "homing (not used)" },
    { "JOINT_#", "TYPE", STR, "", "", 0, IGN, "", "LinuxCNC's joint type; legs are linear" },

    /* [AXIS_X] .. [AXIS_C]: soft limits of the pose (kins/hexapod_workspace.c) */
    { "AXIS_X", "MIN_LIMIT", NUM, "mm", "", 0, 0, "", "soft limit: the pose's X in machine coordinates stays at or above it (jog, MDI, check, run); absent: none" },
    { "AXIS_X", "MAX_LIMIT", NUM, "mm", "", 0, 0, "", "soft limit: the pose's X stays at or below it; absent: none" },
    { "AXIS_Y", "MIN_LIMIT", NUM, "mm", "", 0, 0, "", "soft limit: the pose's Y in machine coordinates stays at or above it (jog, MDI, check, run); absent: none" },
    { "AXIS_Y", "MAX_LIMIT", NUM, "mm", "", 0, 0, "", "soft limit: the pose's Y stays at or below it; absent: none" },
    { "AXIS_Z", "MIN_LIMIT", NUM, "mm", "", 0, 0, "", "soft limit: the pose's Z in machine coordinates stays at or above it (jog, MDI, check, run); absent: none" },
    { "AXIS_Z", "MAX_LIMIT", NUM, "mm", "", 0, 0, "", "soft limit: the pose's Z stays at or below it; absent: none" },
    { "AXIS_A", "MIN_LIMIT", NUM, "deg", "", 0, 0, "", "soft limit: the pose's A in machine coordinates stays at or above it (jog, MDI, check, run); absent: none" },
    { "AXIS_A", "MAX_LIMIT", NUM, "deg", "", 0, 0, "", "soft limit: the pose's A stays at or below it; absent: none" },
    { "AXIS_B", "MIN_LIMIT", NUM, "deg", "", 0, 0, "", "soft limit: the pose's B in machine coordinates stays at or above it (jog, MDI, check, run); absent: none" },
    { "AXIS_B", "MAX_LIMIT", NUM, "deg", "", 0, 0, "", "soft limit: the pose's B stays at or below it; absent: none" },
    { "AXIS_C", "MIN_LIMIT", NUM, "deg", "", 0, 0, "", "soft limit: the pose's C in machine coordinates stays at or above it (jog, MDI, check, run); absent: none" },
    { "AXIS_C", "MAX_LIMIT", NUM, "deg", "", 0, 0, "", "soft limit: the pose's C stays at or below it; absent: none" },
    { "AXIS_X", "MAX_VELOCITY", NUM, "", "", 0, IGN, "", "LinuxCNC's axis speed (hexcnc: [TRAJ] and the legs)" },
    { "AXIS_X", "MAX_ACCELERATION", NUM, "", "", 0, IGN, "", "LinuxCNC's axis acceleration" },
    { "AXIS_X", "MAX_JERK", NUM, "", "", 0, IGN, "", "LinuxCNC's axis jerk" },
    { "AXIS_X", "OFFSET_AV_RATIO", NUM, "", "", 0, IGN, "", "LinuxCNC's external offsets share" },
    { "AXIS_X", "WRAPPED_ROTARY", STR, "", "", 0, IGN, "", "LinuxCNC's wrapped rotary axis" },
    { "AXIS_X", "LOCKING_INDEXER_JOINT", STR, "", "", 0, IGN, "", "LinuxCNC's locking indexer" },
    { "AXIS_Y", "MAX_VELOCITY", NUM, "", "", 0, IGN, "", "LinuxCNC's axis speed (hexcnc: [TRAJ] and the legs)" },
    { "AXIS_Y", "MAX_ACCELERATION", NUM, "", "", 0, IGN, "", "LinuxCNC's axis acceleration" },
    { "AXIS_Y", "MAX_JERK", NUM, "", "", 0, IGN, "", "LinuxCNC's axis jerk" },
    { "AXIS_Y", "OFFSET_AV_RATIO", NUM, "", "", 0, IGN, "", "LinuxCNC's external offsets share" },
    { "AXIS_Y", "WRAPPED_ROTARY", STR, "", "", 0, IGN, "", "LinuxCNC's wrapped rotary axis" },
    { "AXIS_Y", "LOCKING_INDEXER_JOINT", STR, "", "", 0, IGN, "", "LinuxCNC's locking indexer" },
    { "AXIS_Z", "MAX_VELOCITY", NUM, "", "", 0, IGN, "", "LinuxCNC's axis speed (hexcnc: [TRAJ] and the legs)" },
    { "AXIS_Z", "MAX_ACCELERATION", NUM, "", "", 0, IGN, "", "LinuxCNC's axis acceleration" },
    { "AXIS_Z", "MAX_JERK", NUM, "", "", 0, IGN, "", "LinuxCNC's axis jerk" },
    { "AXIS_Z", "OFFSET_AV_RATIO", NUM, "", "", 0, IGN, "", "LinuxCNC's external offsets share" },
    { "AXIS_Z", "WRAPPED_ROTARY", STR, "", "", 0, IGN, "", "LinuxCNC's wrapped rotary axis" },
    { "AXIS_Z", "LOCKING_INDEXER_JOINT", STR, "", "", 0, IGN, "", "LinuxCNC's locking indexer" },
    { "AXIS_A", "MAX_VELOCITY", NUM, "", "", 0, IGN, "", "LinuxCNC's axis speed (hexcnc: [TRAJ] and the legs)" },
    { "AXIS_A", "MAX_ACCELERATION", NUM, "", "", 0, IGN, "", "LinuxCNC's axis acceleration" },
    { "AXIS_A", "MAX_JERK", NUM, "", "", 0, IGN, "", "LinuxCNC's axis jerk" },
    { "AXIS_A", "OFFSET_AV_RATIO", NUM, "", "", 0, IGN, "", "LinuxCNC's external offsets share" },
    { "AXIS_A", "WRAPPED_ROTARY", STR, "", "", 0, IGN, "", "LinuxCNC's wrapped rotary axis" },
    { "AXIS_A", "LOCKING_INDEXER_JOINT", STR, "", "", 0, IGN, "", "LinuxCNC's locking indexer" },
    { "AXIS_B", "MAX_VELOCITY", NUM, "", "", 0, IGN, "", "LinuxCNC's axis speed (hexcnc: [TRAJ] and the legs)" },
    { "AXIS_B", "MAX_ACCELERATION", NUM, "", "", 0, IGN, "", "LinuxCNC's axis acceleration" },
    { "AXIS_B", "MAX_JERK", NUM, "", "", 0, IGN, "", "LinuxCNC's axis jerk" },
    { "AXIS_B", "OFFSET_AV_RATIO", NUM, "", "", 0, IGN, "", "LinuxCNC's external offsets share" },
    { "AXIS_B", "WRAPPED_ROTARY", STR, "", "", 0, IGN, "", "LinuxCNC's wrapped rotary axis" },
    { "AXIS_B", "LOCKING_INDEXER_JOINT", STR, "", "", 0, IGN, "", "LinuxCNC's locking indexer" },
    { "AXIS_C", "MAX_VELOCITY", NUM, "", "", 0, IGN, "", "LinuxCNC's axis speed (hexcnc: [TRAJ] and the legs)" },
    { "AXIS_C", "MAX_ACCELERATION", NUM, "", "", 0, IGN, "", "LinuxCNC's axis acceleration" },
    { "AXIS_C", "MAX_JERK", NUM, "", "", 0, IGN, "", "LinuxCNC's axis jerk" },
    { "AXIS_C", "OFFSET_AV_RATIO", NUM, "", "", 0, IGN, "", "LinuxCNC's external offsets share" },
    { "AXIS_C", "WRAPPED_ROTARY", STR, "", "", 0, IGN, "", "LinuxCNC's wrapped rotary axis" },
    { "AXIS_C", "LOCKING_INDEXER_JOINT", STR, "", "", 0, IGN, "", "LinuxCNC's locking indexer" },

    /* [RS274NGC] */
    { "RS274NGC", "FEED_UNITS", ENUM, "", "mm/min|m/min", 0, 0, "mm/min", "unit of F in G21 "
      "programs (RS274/NGC's is mm/min)" },
    { "RS274NGC", "TOOL_TABLE", PATH, "", "", 0, 0, "", "tool table (LinuxCNC's format)" },
    { "RS274NGC", "PARAMETER_FILE", PATH, "", "", 0, 0, "", "numbered parameters kept "
      "between runs" },
    { "RS274NGC", "SUBROUTINE_PATH", STR, "", "", 0, 0, "", "folders (':' separated, relative "
      "to the INI) where `o<name> call` finds name.ngc, after the program's folder" },
    { "RS274NGC", "LOOP_LIMIT", INT, "", "> 0", 0, 0, "10000000", "loop iterations (while, "
      "do, repeat) one program may run before it is refused as a loop that never ends" },
    /* [SPINDLE_SYNC]: no defaults; a program with G33 or G33.1 is refused without them */
    { "SPINDLE_SYNC", "ACCELERATION", NUM, "rpm/s", "> 0", 0, 0, "", "how fast the spindle "
      "gains or loses speed: the path must follow it, and a rigid tap (G33.1) runs on past "
      "its bottom by K x the revolutions the spindle takes to stop before it reverses" },
    { "SPINDLE_SYNC", "SPEED_MARGIN", NUM, "", "> 0", 0, 0, "", "how much faster than "
      "commanded the spindle may turn, as a fraction (0.1: 10 %); a synchronised move is "
      "refused where the path or legs could not keep up with S x K at that speed, and the "
      "path catches up with the turning spindle at the margin's share of that speed" },
    /* [PROBE] */
    { "PROBE", "MODEL", ENUM, "", "NONE|PLANE|BOX", 0, 0, "NONE", "the workpiece G38.2..G38.5 "
      "probe in `hexcnc interp -i` and `hexcnc check`: NONE (as LinuxCNC's rs274: no trip, "
      "0.254 mm short of the end), PLANE (material below PLANE_POINT, PLANE_NORMAL) or BOX "
      "(BOX_MIN..BOX_MAX)" },
    { "PROBE", "PLANE_POINT", NUMS, "mm", "", 3, 0, "", "MODEL = PLANE: a point x y z of the "
      "surface, machine coordinates" },
    { "PROBE", "PLANE_NORMAL", NUMS, "", "", 3, 0, "", "MODEL = PLANE: the surface's normal x "
      "y z, pointing out of the material (any length but 0)" },
    { "PROBE", "BOX_MIN", NUMS, "mm", "", 3, 0, "", "MODEL = BOX: the block's corner with the "
      "smallest x y z, machine coordinates" },
    { "PROBE", "BOX_MAX", NUMS, "mm", "", 3, 0, "", "MODEL = BOX: the block's corner with the "
      "largest x y z, machine coordinates" },
    { "EMCIO", "TOOL_TABLE", PATH, "", "", 0, 0, "", "tool table, when [RS274NGC] has none "
      "(LinuxCNC's place for it)" },

    /* [HAL], [TASK], [DISPLAY] */
    { "HAL", "HALFILE", PATH, "", "", 0, REP, "", "HAL file run at start, in order" },
    { "HAL", "TWOPASS", STR, "", "", 0, IGN, "", "LinuxCNC's two-pass HAL loading" },
    { "HAL", "POSTGUI_HALFILE", PATH, "", "", 0, IGN, "", "LinuxCNC GUIs' HAL file" },
    { "TASK", "HALFILE", PATH, "", "", 0, REP, "", "HAL file `hexcnc run` runs after [HAL]'s "
      "(its task.* pins)" },
    { "TASK", "PROGRESS_INTERVAL", INT, "s", "> 0", 0, 0, "5", "longest machine time "
      "between progress lines (they also come at every 10 % and every wall second)" },
    { "TASK", "MAX_PROGRAM_MB", INT, "MB", "> 0", 0, 0, "64", "largest program file "
      "`hexcnc run` loads (10^6 bytes); a larger one is refused before it is read" },
    { "API", "SOCKET", PATH, "", "", 0, 0, "$XDG_RUNTIME_DIR/hexcnc.sock", "Unix socket of "
      "`hexcnc machine` (else /tmp/hexcnc-UID/hexcnc.sock)" },
    { "API", "GROUP", STR, "", "", 0, 0, "", "group allowed to use the socket (mode 0660); "
      "absent: its owner only (0600)" },
    { "API", "HTTP", STR, "", "", 0, 0, "127.0.0.1:8080", "address and port of the "
      "operator's station (`hexcnc web`, docs/ui.md); an address other than loopback needs "
      "TOKEN_FILE" },
    { "API", "TOKEN_FILE", PATH, "", "", 0, 0, "", "file (mode 600) whose first line is the "
      "secret a browser must present to the station (16+ characters)" },
    { "API", "ALLOWED_ORIGINS", STR, "", "", 0, 0, "", "further origins (scheme://host:port) "
      "whose pages may open the station's WebSocket, besides its own address" },
    { "API", "UI_DIR", PATH, "", "", 0, 0, "share/hexcnc/ui beside bin/", "folder of the "
      "built page the station serves" },
    { "DISPLAY", "PROGRAM_PREFIX", PATH, "", "", 0, 0, "the INI's folder", "folder programs "
      "are opened from by relative paths (the station: only from here; uploads go here)" },
    { "TASK", "TASK", STR, "", "", 0, IGN, "", "LinuxCNC's task program" },
    { "TASK", "CYCLE_TIME", NUM, "s", "", 0, IGN, "", "LinuxCNC's task period" },
    { "DISPLAY", "OPEN_FILE", PATH, "", "", 0, 0, "", "program `hexcnc run` runs when none "
      "is given" },

    /* [LCM] */
    { "LCM", "URL", STR, "", "", 0, 0, "", "LCM URL to publish status on (empty: none)" },
    { "LCM", "RATE_HZ", NUM, "1/s", "> 0", 0, 0, "20", "status messages per second" },

    /* [MODBUS] (and [MODBUS_DRIVE_#]) */
    { "MODBUS", "DRIVES", INT, "", "1..64", 0, 0, "1", "number of drives" },
    { "MODBUS", "TRANSPORT", ENUM, "", "tcp|rtu", 0, 0, "tcp", "Modbus TCP or RTU (serial)" },
    { "MODBUS", "HOST", STR, "", "", 0, 0, "127.0.0.1", "TCP: the drive's IPv4 address" },
    { "MODBUS", "PORT", INT, "", "1..65535", 0, 0, "502", "TCP port" },
    { "MODBUS", "BASE_PORT", INT, "", "1..65535", 0, 0, "", "TCP: drive n listens on "
      "BASE_PORT + n" },
    { "MODBUS", "DEVICE", STR, "", "", 0, 0, "", "RTU: serial device (/dev/ttyUSB0)" },
    { "MODBUS", "BAUD", INT, "bit/s", "50..4000000", 0, 0, "115200", "RTU: baud rate" },
    { "MODBUS", "PARITY", ENUM, "", "N|E|O", 0, 0, "N", "RTU: parity" },
    { "MODBUS", "DATA_BITS", INT, "", "5..8", 0, 0, "8", "RTU: data bits" },
    { "MODBUS", "STOP_BITS", INT, "", "1..2", 0, 0, "1", "RTU: stop bits" },
    { "MODBUS", "UNIT", INT, "", "0..255", 0, 0, "1", "Modbus unit (slave) id" },
    { "MODBUS", "REG_CONTROL", INT, "", "0..65535", 0, 0, "0", "control word register" },
    { "MODBUS", "REG_TARGET", INT, "", "0..65534", 0, 0, "1", "target position (two "
      "registers)" },
    { "MODBUS", "REG_STATUS", INT, "", "0..65535", 0, 0, "10", "status word register" },
    { "MODBUS", "REG_ACTUAL", INT, "", "0..65534", 0, 0, "11", "actual position (two "
      "registers)" },
    { "MODBUS", "WORD_ORDER", ENUM, "", "high-first|low-first", 0, 0, "high-first", "order of "
      "a position's two registers" },
    { "MODBUS", "COUNTS_PER_MM", NUM, "counts/mm", "!= 0", 0, 0, "1000", "position counts per "
      "mm of leg (negative reverses)" },
    { "MODBUS", "SETPOINT_PERIOD", INT, "ns", "10000..1e9", 0, 0, "1000000", "period of the "
      "exchanges with a drive" },
    { "MODBUS", "TIMEOUT", NUM, "ms", "> 0", 0, 0, "20", "reply time-out of one exchange" },
    { "MODBUS", "EXCHANGE", ENUM, "", "fc23|separate", 0, 0, "fc23", "one read/write request "
      "(FC 23) or a write and a read" },
    { "MODBUS_SIM", "TAU", NUM, "s", "> 0", 0, 0, "0.002", "simulated drive's position lag "
      "time constant" },
    { "MODBUS_SIM", "MAX_VELOCITY", NUM, "mm/s", ">= 0", 0, 0, "0", "simulated drive's speed "
      "limit (0: none)" },

    /* [CAN], [CAN_NODE_#] */
    { "CAN", "INTERFACE", STR, "", "", 0, 0, "", "SocketCAN interface (can0, vcan0), or "
      "unix:PATH: a SOCK_SEQPACKET socket carrying one CAN frame a message" },
    { "CAN", "SYNC_PERIOD", INT, "ns", "> 0", 0, 0, "servo period", "SYNC period, a multiple "
      "of the servo period" },
    { "CAN", "BITRATE", INT, "bit/s", "> 0", 0, 0, "1000000", "bus bit rate, for the bus "
      "load check" },
    { "CAN", "HEARTBEAT_PERIOD", INT, "ms", "> 0", 0, 0, "20", "drives' heartbeat period" },
    { "CAN", "HEARTBEAT_TIMEOUT", INT, "ms", "> 0", 0, 0, "100", "a drive is lost after this "
      "long without a heartbeat" },
    { "CAN", "BOOT_TIMEOUT", INT, "ms", "> 0", 0, 0, "1000", "time a drive has to boot" },
    { "CAN", "FEEDBACK_TIMEOUT_SYNCS", INT, "SYNC periods", "1..1000", 0, 0, "3", "position "
      "feedback (TPDO1) missing for longer than this many SYNC periods is a fault" },
    { "CAN_NODE_#", "NODE_ID", INT, "", "1..127", 0, REQ, "", "CANopen node id" },
    { "CAN_NODE_#", "COUNTS_PER_MM", NUM, "counts/mm", "!= 0", 0, REQ, "", "position counts "
      "per mm of leg (negative reverses)" },
    { "CAN_NODE_#", "OFFSET", NUM, "mm", "", 0, 0, "0", "leg length at position 0" },
    { "CAN_NODE_#", "SDO_TIMEOUT", INT, "ms", "> 0", 0, 0, "100", "SDO reply time-out" },
    { "CAN_NODE_#", "SIM_START", NUM, "mm", "", 0, 0, "OFFSET", "simulated drive: leg length "
      "at power-on" },
    { "CAN_NODE_#", "SIM_BOOT_DELAY", NUM, "ms", "0..60000", 0, 0, "0", "simulated drive: "
      "boot-up delay after power-on or NMT reset" },
    { "CAN_NODE_#", "SIM_MAX_VELOCITY", NUM, "mm/s", ">= 0", 0, 0, "0", "simulated drive: "
      "speed limit (0: none)" },
};
const int config_nkeys = sizeof config_keys / sizeof config_keys[0];
