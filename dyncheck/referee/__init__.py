"""The referee: the book's general method (``reference/``, (2.2.23)–(2.2.26)) on the neutral
tree an engine read, tied to the recursive algorithm on that very tree, and its derivatives in
the canonical chart — one home for ``dyncheck run`` (a case's derivative rows), ``check``
(every section) and ``explain`` (the catalogue's demonstrations).

- :mod:`.states`: the sampled states every comparison takes, and M's conditioning over them;
- :mod:`.computed`: a neutral tree as the general method takes it, and what an engine
  computing with other values than it holds changes;
- :mod:`.tree`: the referee on a tree (the general method, the recursive algorithm, their
  tie);
- :mod:`.charts`: the canonical chart (q ⊕ δ) and an engine's derivatives mapped into it;
- :mod:`.derivatives`: the referee's derivatives by a complex step.
"""
