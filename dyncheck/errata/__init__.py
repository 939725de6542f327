"""Errata of §2.2: every formula of the chapter inventoried (:mod:`.inventory`), each checked
(:mod:`.checks`) and the verdicts rendered (:mod:`.page`)."""
