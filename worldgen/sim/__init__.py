"""Running worlds in real simulators: ``gazebo`` (a headless Gazebo Sim server driven from Python), with the
child-process handling (``procs``) and the protobuf text its command-line tools print (``textproto``)."""

__all__: list[str] = []
