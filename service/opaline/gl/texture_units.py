"""Every texture unit a surface sample binds, in one table: two passes that bound one unit
each once read the environment map as the thickness field."""

ACCUMULATE_SOURCE = 0  # the accumulate and resolve passes' source
NORMAL_MAP = 1
THICKNESS_MAP = 2
ENVIRONMENT = 3  # the background pass and environment light read the same map
WEIGHT_MAP = 4
