"""The parametric human body: its skeleton (joint, link and landmark names, joint groups and
self-collision groups: ``skeleton``) and measurements (``body``), rendered through
``templates/person/person.urdf.xacro``."""
