"""Figures every method shares, drawn only from run files and tables made from them (each method draws
its own in ``methods/<name>/``).  Every public function has the signature ``f(inputs..., outputs, **kw)``;
``style`` owns the look and the one ``save``."""
