"""The parametric human body: measurements, landmark names, joint groups and self-collision
groups (``body``), rendered through ``templates/person/person.urdf.xacro``."""
