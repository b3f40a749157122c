"""The papers, one plug-in folder each (``paperNNN/``): scenarios, metric sets, commands, report section,
data and tests. A folder is registered by one line in ``pyproject.toml``
(``[project.entry-points."scfmu.plugins"]``); its ``register(registry)`` fills the registry."""
