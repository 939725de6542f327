"""``dyncheck bench``'s work: the engines' per-state costs against each other and a sweep in
slices (:mod:`.engines`), and the wall time of whole commands (:mod:`.suite`, ``--suite``)."""
