"""The choices ``rough report`` takes, in a module that loads nothing, so that ``rough
report --help`` costs no numpy."""

#: The parameter sets, after ISO 25178-2's classes: heights, spatial, hybrid,
#: functional (material ratio, ISO 13565), feature (watershed), and the rest
#: (peak density, Z2, JRC).
SETS = ("height", "spatial", "hybrid", "functional", "feature", "other")
#: The formats a report is written in.
FORMATS = ("html", "pdf")
