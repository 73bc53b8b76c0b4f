"""People: where they start and go (:mod:`~worldgen.people.places`), the social force model that walks
them round the exact geometry (:mod:`~worldgen.people.crowd`, groups in :mod:`~worldgen.people.groups`)
and the timed path among them that certifies a task (:mod:`~worldgen.people.timed`); docs/people.md.

It proves things with :mod:`worldgen.feasibility` (the exact planner and its tangent graph); feasibility
never imports it."""

__all__: list[str] = []
