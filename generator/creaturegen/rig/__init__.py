"""Rig compiler: parts to primitive slots, the blend program, and the cache identities."""

from .compile import CompiledRig, RigCompileError, compile_rig

__all__ = ["CompiledRig", "RigCompileError", "compile_rig"]
