"""Model files, shared by every engine: reading a user's MJCF or URDF (:mod:`.files`), MJCF's
toolkit — includes inlined, defaults, assets, copies for a parser (:mod:`.mjcf_copy`), what no
engine reads (:mod:`.mjcf_unread`) — and a book case written as MJCF (:mod:`.mjcf`) or URDF
(:mod:`.urdf`). No engine is imported here."""
