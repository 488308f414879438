"""Locomotion reference: the float64 formulas the generated JS core (core/motion/) runs in the same order.

Pure Python floats, written operation for operation like the JS, so the two agree to ~1e-15 after
thousands of ticks; numpy is not used in the per-tick path because its vector kernels may reorder sums.
"""
