"""The book, clean-room: §2.2 "Dynamics" of J. H. Heinbockel, *Introduction to Tensor
Calculus and Continuum Mechanics* (Old Dominion University; Trafford, 2001), its equations
implemented from the text alone and cited by number, e.g. (2.2.23).

Imports numpy, scipy and sympy only — never an engine.
"""
