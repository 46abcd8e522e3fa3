/* The firmware side of an exported colcos policy (examples/onboard_export.py), as the smallest program
 * that links for a Cortex-M4F: scripts/onboard_footprint.sh builds it twice, with and without the
 * policy (-DWITH_POLICY=1 / 0), and the difference is what the policy costs in flash, libm included.
 * The sensor and motor functions stand in for the robot's drivers (volatile: the compiler keeps them). */
#include <stdint.h>

#if WITH_POLICY
#include "policy.h"
#endif

static volatile uint16_t sensor_regs[18];
static volatile float motor_regs[2];

static void read_colour_sensors(uint16_t colour[12])
{
    int k;
    for (k = 0; k < 12; ++k)
        colour[k] = sensor_regs[k];
}

static void read_bumpers(uint16_t ir_on[3], uint16_t ir_off[3])
{
    int k;
    for (k = 0; k < 3; ++k) {
        ir_on[k] = sensor_regs[12 + k];
        ir_off[k] = sensor_regs[15 + k];
    }
}

static void set_wheel_speeds(float left, float right)
{
    motor_regs[0] = left;
    motor_regs[1] = right;
}

static float left = 0.0f, right = 0.0f; /* the wheel speeds last commanded, m/s */

/* Once per control tick (a timer interrupt at 50 Hz on the robot). */
static void control_tick(void)
{
    uint16_t colour[12], ir_on[3], ir_off[3];
    read_colour_sensors(colour);
    read_bumpers(ir_on, ir_off);
#if WITH_POLICY
    colcos_policy_step(colour, ir_on, ir_off, &left, &right);
#else
    left = (float)(colour[0] + ir_on[0] - ir_off[0]) * 1e-6f;
    right = left;
#endif
    set_wheel_speeds(left, right);
}

int main(void)
{
    for (;;)
        control_tick();
}
