"""Drawing the teaching aids' arrows and the inspector's words: vectors, the centre of mass, forces.

The numbers come from model/aids.py and the table; the pixels from the
window's AidsPainter. The Aids feature (teaching_aids.py) calls these after
the table is drawn.
"""

from __future__ import annotations

import numpy as np

from airtable.model import aids
from airtable.model.momenta import puck_number
from airtable.model.readout import SceneScale, figures, fixed

DIM_FORCE = (200, 200, 200)
COM_COLOR = (255, 255, 255)
FORCE_COLORS = {"cursor strings": (255, 120, 80), "springs": (255, 215, 0), "gravity": (90, 160, 255)}


# A puck in a jelly can have a dozen springs; the inspector lists the first few.
MAX_INSPECTED_SPRINGS = 4


def inspector_lines(table, puck, scale: SceneScale | None = None) -> list[str]:
    """What `i` tells about a puck: mass, speed, energy, and each spring on it with the stiffness it acts
    with. Round-off shows as 0 by the scene's `scale` (readout.py): a speed by the momentum it gives."""
    scale, m = scale or SceneScale(), puck.mass_kg
    v = [scale.momentum(m * c) / m if m > 0 else float(c) for c in puck.vel_mps]
    speed = float(np.hypot(*v))
    lines = [
        f"puck {puck_number(puck.index)}",
        f"mass {figures(m, 4)} kg   radius {figures(puck.radius_m, 4)} m",
        f"speed {figures(speed, 4)} m/s",
        f"velocity ({fixed(v[0], 3)}, {fixed(v[1], 3)}) m/s",
        f"kinetic energy {figures(scale.energy(0.5 * m * speed**2), 4)} J",
    ]
    if table.asleep[puck.index]:  # the engine's sleeping, made visible (physics/sleep.py)
        lines.append("asleep: the step skips it until disturbed")
    for spring in table.springs_on(puck)[:MAX_INSPECTED_SPRINGS]:
        other = spring.p2 if spring.p1.index == puck.index else spring.p1
        line = f"spring to puck {puck_number(other.index)}: k {figures(spring.k_Npm, 4)} N/m"
        if spring.k_effective_Npm != spring.k_Npm:
            line += f", acts with {figures(spring.k_effective_Npm, 4)} N/m (softened)"
        lines.append(line)
    return lines


def draw_vectors(paint, t, which: int, held, forces) -> None:
    """Arrows on the moving pucks of table `t` at the demo's fixed round scale (`which`: 1 velocity,
    2 momentum), the centre of mass, and `forces` (source -> newtons) on the `held` puck."""
    speed = np.hypot(t.vel_mps[:, 0], t.vel_mps[:, 1])
    moving = speed >= aids.MIN_ARROW_SPEED_MPS  # a resting puck gets no arrow
    if which == 1:
        name, unit, values, color = "velocity", "m/s", t.vel_mps, (120, 220, 255)
    else:
        name, unit, values, color = "momentum", "N s", t.vel_mps * t.mass_kg[:, None], (230, 120, 230)
    amount, m_per_unit = paint.vector_scale(name).update(values[moving])
    paint.arrows(t.pos_m[moving], values[moving] * m_per_unit, color)
    legend = [(f"{name}: an arrow 1 m long is {amount:g} {unit}", color)]
    # The centre of mass moves in a straight line while no outside force acts.
    com, com_v = t.center_of_mass_m(), t.center_of_mass_vel_mps()
    _, m_per_mps = paint.vector_scale("velocity").update(t.vel_mps[moving])
    if np.hypot(*com_v) >= aids.MIN_ARROW_SPEED_MPS:
        paint.arrow(com, com_v * m_per_mps, COM_COLOR, width=paint.w.line_px(3))
    if held is not None:
        legend.extend(_draw_forces(paint, held, forces))
    paint.legend(legend)  # before the marker's label: the legend's place is fixed
    paint.marker(com, COM_COLOR, f"centre of mass, {np.hypot(*com_v):.2f} m/s")


def _draw_forces(paint, held, forces) -> list[tuple[str, tuple[int, int, int]]]:
    """Arrows of the forces on the held puck, scaled to round newtons; their legend lines."""
    if not forces:
        return []
    biggest = max(float(np.hypot(*f)) for f in forces.values())
    newtons, m_per_n = aids.nice_scale(biggest, target_m=1.0)
    legend = []
    for source, f in forces.items():
        c = FORCE_COLORS[source]
        paint.arrow(held.pos_m, f * m_per_n, c, width=paint.w.line_px(3))
        legend.append((f"force, {source}: {figures(np.hypot(*f))} N", c))
    legend.append((f"forces: an arrow 1 m long is {newtons:g} N", DIM_FORCE))
    return legend
