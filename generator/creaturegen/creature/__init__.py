"""The creature package: build plan, program tapes, the closed-form sway pose, and the package writer."""
