"""``creaturegen build-many``: many specs at several tiers, on a local process pool or a Dask cluster.

specs.py names and validates the inputs, task.py is what a worker runs (one build or one parity job, in
its own process), engines.py hands tasks to a local pool or to Dask, results.py keeps every outcome by a
key of its inputs (a rerun skips what is done), gallery.py draws OUT/index.html, run.py ties them together.
"""
