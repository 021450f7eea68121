"""Headless part of TopOpt: never imports FreeCADGui or PySide."""
