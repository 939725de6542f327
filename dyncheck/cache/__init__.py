"""The cache folder (``$DYNCHECK_CACHE`` or ``~/.cache/dyncheck``), one home: the store that
reads and writes it as untrusted input (:mod:`.store`), the measured demonstrations, figures
and reference trajectories kept there by a fingerprint of everything that made them
(:mod:`.measured`), and the engines' compiled code, each entry vouched for by an
authenticated manifest (:mod:`.compiled`)."""
