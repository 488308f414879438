"""Body plans of the corpus generator, one module per locomotion type: a walker's torso on legs
(quadrupeds, hexapods, octopods), an upright biped with arms, a hopper's round body (or a kangaroo), a
flyer's wings, a swimmer's fins and tail, and a still creature. Each places the parts of its plan, with the
features that suit it, on a ``Creature``.
"""
