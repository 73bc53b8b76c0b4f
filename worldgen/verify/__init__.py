"""Re-checking a world someone received (``worldgen check``): hashes, schema, regeneration with its edits
replayed (:mod:`~worldgen.verify.edits`), feasibility, the timed certificate among people
(:mod:`~worldgen.verify.timed`) and byte-for-byte export (:mod:`~worldgen.verify.folder`)."""

from worldgen.verify.folder import CHECKS, LENGTH_TOLERANCE, Outcome, check_folder

__all__ = ["check_folder", "Outcome", "CHECKS", "LENGTH_TOLERANCE"]
