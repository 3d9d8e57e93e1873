"""One printer per shader language (sympy `CodePrinter` subclasses) with its function
spellings (`known_functions`); the target registry that names them is implc/targets.py."""
