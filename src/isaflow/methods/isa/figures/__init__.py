"""ISA's figures (paper Figs. 5-10, calibration, convergence, flow history, the study), drawn only from
run files and tables made from them.  Every public function has the signature ``f(inputs, outputs, **kw)``."""
