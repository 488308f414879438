"""The base layer: what every stage shares and nothing above it defines.

The slot table's column layout, the slot skeleton, and poses with the rotations and quaternions
(w, x, y, z) that move it. Modules here import only ``spec``, numpy and each other, so every stage
(field, rig, motion, candidates, surface, creature) can build on them without importing another stage
(tests/test_layers.py holds the line).
"""
