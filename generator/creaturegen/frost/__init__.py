"""Frost/thaw surface effect: law, brush, reference simulation, static structure."""
