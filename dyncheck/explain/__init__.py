"""``dyncheck explain``'s work, one home for the conventions: the catalogue that names each
demonstration and runs it (:mod:`.catalogue`), the demonstrations, one module per topic, an
entry and its text (:mod:`.entry`), the measurements they share (:mod:`.measure`), every
label that explains a row with its text and origin (:mod:`.explanations`), the engines'
defects as standalone reproducers (:mod:`.reproducers`) and what an engine's changelog says
about a step of the version matrix (:mod:`.releases`)."""
