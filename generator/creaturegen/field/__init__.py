"""The CPU reference field: primitive distances, blend operators, the sampler and proximity colour (numpy)."""
