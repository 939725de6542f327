"""The book, clean-room: §2.2's equations implemented from the text alone.

Imports numpy, scipy and sympy only — never an engine.
"""
