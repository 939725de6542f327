"""Model files, shared by every engine: reading a user's MJCF or URDF (:mod:`.files`) through
the XML the engines' parsers accept (:mod:`.parsing`); MJCF's includes and asset files as
MuJoCo resolves them (:mod:`.includes`), the copy a parser that cannot read all of a file is
given (:mod:`.mjcf_copy`), what no engine reads (:mod:`.mjcf_unread`); and a book case written
as MJCF (:mod:`.mjcf`) or URDF (:mod:`.urdf`). No engine is imported here."""
