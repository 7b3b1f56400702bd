"""Warnings point at the user's line (issue 34): whatever the depth of the call inside mbdsim
(decorators, the solver's assembly, a Result's reactions), a warning's filename is the calling file,
here this test file."""
import warnings

import mbdsim as mb
from mbdsim._userwarn import user_stacklevel


def door(velocity=None):
    """A door on two coaxial hinges (redundant); `velocity` [m/s] given to its centre of mass."""
    m = mb.Model("door", gravity=(0, -9.81, 0))
    leaf = m.add_body("leaf", mass=10.0, inertia=(0.5, 0.5, 0.5), position=(0.4, 0, 0), velocity=velocity)
    m.add_revolute("upper", m.ground, leaf, (0, 0, 1), (0, 0, 1))
    m.add_revolute("lower", m.ground, leaf, (0, 0, -1), (0, 0, 1))
    return m


def caught(fn, category):
    with warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always")
        fn()
    found = [w for w in got if issubclass(w.category, category)]
    assert found, [str(w.message) for w in got]
    return found


def test_assembly_warnings_name_the_calling_file():
    m = door(velocity=(1, 0, 0))    # radial: the hinges cannot hold it
    for w in caught(lambda: mb.assemble(m), mb.InitialConditionWarning) + \
            caught(lambda: mb.assemble(m), mb.RedundantConstraintWarning):
        assert w.filename == __file__, (w.filename, w.lineno)


def test_simulate_warnings_name_the_calling_file():
    m = door(velocity=(1, 0, 0))
    for w in caught(lambda: mb.simulate(m, 0.01, 0.01), mb.InitialConditionWarning):
        assert w.filename == __file__, (w.filename, w.lineno)


def test_result_warnings_name_the_calling_file():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = mb.simulate(door(), 0.01, 0.01)
    for w in caught(lambda: res.reaction_force("upper"), mb.IndeterminateReactionWarning):
        assert w.filename == __file__, (w.filename, w.lineno)


def test_stacklevel_outside_the_package_is_the_direct_caller():
    def here():
        return user_stacklevel()
    assert here() == 2
