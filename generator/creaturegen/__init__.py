"""creaturegen: a compiler from small JSON specs to Three.js r185 WebGPU/TSL npm packages."""

__version__ = "0.1.0"
