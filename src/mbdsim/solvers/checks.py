"""Checks of the assembled initial state before a dynamic analysis starts.

Contact penetration: a compliant contact starting deep inside its partner stores an elastic energy the
model never had (a 1 m penetration of a 1e5 N/m^1.5 contact shoots the body off at ~10^4 m/s).
At the assembled state, for every sphere-plane / sphere-sphere contact with depth delta = -gap [m]:

- delta >= the sphere radius (the centre on or past the surface; the smaller sphere of two): ModelError
  naming the contact and `initial_gap` - the contact normal is meaningless there;
- delta > INITIAL_PENETRATION_FACTOR x the contact's `penetration` (its damping ramp depth, the scale of a
  working penetration): InitialPenetrationWarning naming the contact, the depth and the stored energy.
"""
from __future__ import annotations



from .._userwarn import warn
from ..errors import ModelError

INITIAL_PENETRATION_FACTOR = 10.0


class InitialPenetrationWarning(UserWarning):
    """A contact starts penetrated well beyond its working depth."""


def check_initial_contacts(sys, q, v) -> None:
    """ModelError / InitialPenetrationWarning for contacts penetrated at the state (q, v), see module doc."""
    from ..model.element_specs import Contact
    contacts = [e for e in sys.model.forces.values() if isinstance(e, Contact)]
    if not contacts:
        return
    from ..system.force_elements._common import batched
    from ..system.force_elements.contact import contact_state
    from ..system.frames import body_frames
    fb, _ = batched(body_frames(sys, q, v))
    for el in contacts:
        g = float(contact_state(sys, fb, el)[0][0])
        depth = -g
        if depth <= 0.0:
            continue
        radius = min(s.radius for s in (el.shape_i, el.shape_j) if s.kind == "sphere")
        entity = f"contact '{el.name}'"
        if depth >= radius:
            raise ModelError(entity, "initial_gap", f"the shapes start {depth:.6g} m inside each other, at least "
                             f"the sphere radius {radius:.6g} m: move the bodies apart")
        if depth > INITIAL_PENETRATION_FACTOR * el.penetration:
            energy = el.stiffness * depth ** (el.exponent + 1) / (el.exponent + 1)
            warn(f"{entity}.initial_gap: the shapes start {depth:.6g} m inside each other (more than "
                 f"{INITIAL_PENETRATION_FACTOR:g} x its penetration {el.penetration:g} m), storing "
                 f"{energy:.6g} J of contact energy at t = 0", InitialPenetrationWarning)
