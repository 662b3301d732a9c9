"""envmis: importance sampling of HDR environment maps, from Python.

The C++ library's maps, tables and sampling (envmis._maps) and its variance study
(envmis._study), with NumPy arrays in and out. Units and measures are those of the C++
headers: directions are unit vectors in the map's world frame, pdfs are per steradian,
radiance is linear RGB in the map's working colour space.
"""

from ._maps import *  # noqa: F401,F403
from ._maps import __version__  # noqa: F401
from ._study import *  # noqa: F401,F403
