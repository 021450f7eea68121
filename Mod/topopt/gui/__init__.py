"""GUI part of TopOpt: commands, task panels, view providers. Imported only with the GUI."""
