"""The physical constants of the firmware side, for the repository's Python
(tools/*/generate.py, python/tests/): each is a decimal literal in
firmware/include/ascorr/core/constants.hpp or ascorr/nav/orbit_propagation.hpp,
the one place it is written; float() of the literal is the same double as the
C++ compiler's."""

import os
import re

_INCLUDE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "firmware", "include", "ascorr")
_HEADERS = ("core/constants.hpp", "nav/orbit_propagation.hpp")


def core_constant(name):
    """The value of `inline constexpr double <name> = <literal>;`."""
    for header in _HEADERS:
        with open(os.path.join(_INCLUDE, header)) as f:
            m = re.search(rf"^inline constexpr double {name} = ([0-9.eE+-]+);", f.read(), re.M)
        if m:
            return float(m.group(1))
    raise KeyError(f"{name}: not a decimal constant of {', '.join(_HEADERS)}")
