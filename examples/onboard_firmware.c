/* The firmware side of an exported colcos policy (examples/onboard_export.py), as the smallest program
 * that links for a Cortex-M4F: scripts/onboard_footprint.sh builds it twice, with and without the
 * policy (-DWITH_POLICY=1 / 0), and the difference is what the policy costs in flash and RAM, libm
 * included. The sensor, motor and radio functions stand in for the robot's drivers (volatile: the
 * compiler keeps them). The radio side is colcos's protocol extension (docs/bridge.md): `PWP` writes
 * the runtime parameters, `PRN` starts the policy if it names this one's hash, any motion command
 * (here `MWS`) takes the robot back to the host's commands, and link silence stops it. */
#include <stdint.h>
#include <string.h>

#if WITH_POLICY
#include "policy.h"
#endif

#define LINK_TIMEOUT_TICKS 25 /* 0.5 s at 50 Hz */

static volatile uint16_t sensor_regs[18];
static volatile float motor_regs[2];
static volatile uint8_t radio_rx[32];
static volatile uint8_t radio_rx_ready;
static volatile uint8_t telemetry_tx[7];

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
static uint32_t silent_ticks = LINK_TIMEOUT_TICKS;

#if WITH_POLICY
enum { MODE_HOST = 1, MODE_RUNNING = 2, MODE_REFUSED = 3 };
static float params[COLCOS_POLICY_N_RUNTIME];
static uint8_t mode = MODE_HOST, writes_ok, writes_refused;

static float f32_at(const uint8_t *p)
{
    float v;
    memcpy(&v, p, 4);
    return v;
}

/* A 32-byte host frame for this robot: id, u32 time, a three-letter command and its arguments. */
static void handle_frame(const uint8_t p[32])
{
    silent_ticks = 0;
    if (memcmp(p + 5, "PWP", 3) == 0) {
        float values[5];
        uint16_t offset = (uint16_t)(p[8] | (p[9] << 8));
        int k;
        for (k = 0; k < 5; ++k)
            values[k] = f32_at(p + 11 + 4 * k);
        if (colcos_policy_write_params(params, offset, p[10], values))
            ++writes_ok;
        else
            ++writes_refused;
    } else if (memcmp(p + 5, "PRN", 3) == 0) {
        uint32_t hash = (uint32_t)p[8] | ((uint32_t)p[9] << 8) | ((uint32_t)p[10] << 16) | ((uint32_t)p[11] << 24);
        if (mode != MODE_RUNNING)
            left = right = 0.0f;
        mode = hash == COLCOS_POLICY_HASH ? MODE_RUNNING : MODE_REFUSED;
    } else if (memcmp(p + 5, "MWS", 3) == 0) {
        mode = MODE_HOST;
        left = f32_at(p + 8);
        right = f32_at(p + 12);
    }
    /* The telemetry's reserved bytes: mode, hash, accepted and refused writes. */
    telemetry_tx[0] = mode;
    telemetry_tx[1] = (uint8_t)COLCOS_POLICY_HASH;
    telemetry_tx[5] = writes_ok;
    telemetry_tx[6] = writes_refused;
}
#endif

/* Once per control tick (a timer interrupt at 50 Hz on the robot). */
static void control_tick(void)
{
    uint16_t colour[12], ir_on[3], ir_off[3];
#if WITH_POLICY
    if (radio_rx_ready) {
        uint8_t frame[32];
        int k;
        for (k = 0; k < 32; ++k)
            frame[k] = radio_rx[k];
        radio_rx_ready = 0;
        handle_frame(frame);
    }
#endif
    if (++silent_ticks > LINK_TIMEOUT_TICKS) {
#if WITH_POLICY
        if (mode == MODE_RUNNING)
            mode = MODE_HOST;
#endif
        left = right = 0.0f;
    }
    read_colour_sensors(colour);
    read_bumpers(ir_on, ir_off);
#if WITH_POLICY
    if (mode == MODE_RUNNING)
        colcos_policy_step_with(params, colour, ir_on, ir_off, &left, &right);
    else if (mode == MODE_REFUSED)
        left = right = 0.0f;
#else
    left += (float)(colour[0] + ir_on[0] - ir_off[0]) * 1e-6f;
#endif
    set_wheel_speeds(left, right);
}

int main(void)
{
#if WITH_POLICY
    colcos_policy_default_params(params);
#endif
    for (;;)
        control_tick();
}
