"""The creature package: build plan, program tapes, pose pages and the seeded LCG, and the package writer."""
