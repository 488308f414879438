"""creaturegen: a compiler from small JSON specs to Three.js r185 WebGPU/TSL npm packages."""

from . import floatenv

floatenv.pin()  # before anything loads numpy: the same bytes on every x86-64 machine (floatenv.py)

__version__ = "0.1.0"
