"""Demo t: pi from collisions: a light puck between a wall and a heavy one counts the digits of pi."""

KEY = "t"
TITLE = "Pi from collisions"
NOTES = """
A heavy puck slides at 1 m/s towards a light one near the left wall, and every hit is
elastic. Count every hit, puck on puck and puck on wall: with the heavy puck 100^n times
heavier the count is 3, 31, 314, 3141, 31415, the first digits of pi (G. Galperin, 2003).
Left/Right change n; at n = 4 the light puck bounces many times in one step, each hit
found in time order; once no more can come (both pucks move away from the wall, the heavy
one faster), the demo says the count and stops both before the far wall sends one back.
"""

N_MAX = 4
VARIATIONS = tuple(f"n = {n}: mass ratio {100**n:,}" for n in range(N_MAX + 1))

LIGHT_RADIUS_M = 0.15
HEAVY_RADIUS_M = 0.45
LIGHT_DENSITY_KGPM2 = 1.0
HEAVY_SPEED_MPS = 1.0
CHECK_EVERY_S = 0.05


def build(table, variation=0):
    """A light puck at rest at x = 1.5 m and a heavy one at 4 m coming at 1 m/s, on one line."""
    n = variation % (N_MAX + 1)
    table.cr_puck = table.cr_wall = 1.0
    table.puck_correction = "perfect-kiss"
    table.rest_speed_mps = 0.0  # every hit is a bounce, however slow
    y_m = table.height_m / 2.0
    light = table.add_puck(pos_m=(1.5, y_m), radius_m=LIGHT_RADIUS_M, density_kgpm2=LIGHT_DENSITY_KGPM2, color="orange")
    # Same mass ratio 100^n whatever the radii: density scales with 1 / r^2.
    heavy_density = LIGHT_DENSITY_KGPM2 * 100**n * (LIGHT_RADIUS_M / HEAVY_RADIUS_M) ** 2
    heavy = table.add_puck(
        pos_m=(4.0, y_m), radius_m=HEAVY_RADIUS_M, density_kgpm2=heavy_density, vel_mps=(-HEAVY_SPEED_MPS, 0.0)
    )

    def stop_when_done(table):
        # Done once both go right and the heavy one is faster: no more hits can come, and the count
        # is said at once. Both stop before the far wall sends the heavy one back.
        v_light, v_heavy = light.vel_mps[0], heavy.vel_mps[0]
        if -1e-12 * abs(v_heavy) <= v_light <= v_heavy:  # (the light one may end at rest but for round-off)
            pairs, walls = table.collision_count, table.wall_collision_count
            table.notices.say(
                "pi",
                f"{pairs + walls} hits in all: {pairs} between the pucks, {walls} on the wall. No more can come.",
            )
            if heavy.pos_m[0] > table.width_m - 3.0 * HEAVY_RADIUS_M:
                light.vel_mps = heavy.vel_mps = (0.0, 0.0)
                return
        table.schedule(table.time_s + CHECK_EVERY_S, stop_when_done)

    table.schedule(CHECK_EVERY_S, stop_when_done)
