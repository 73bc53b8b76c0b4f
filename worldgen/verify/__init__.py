"""Re-checking a world someone received (``worldgen check``): hashes, schema, regeneration with its edits
replayed (:mod:`~worldgen.verify.edits`, the people of an edited world walked again and certified:
:mod:`~worldgen.verify.rewalk`), feasibility, the timed certificate among people
(:mod:`~worldgen.verify.timed`) and byte-for-byte export (:mod:`~worldgen.verify.folder`, which also
rebuilds the World a folder holds: ``load_world``)."""

from worldgen.verify.folder import CHECKS, LENGTH_TOLERANCE, Outcome, check_folder, load_world

__all__ = ["check_folder", "load_world", "Outcome", "CHECKS", "LENGTH_TOLERANCE"]
