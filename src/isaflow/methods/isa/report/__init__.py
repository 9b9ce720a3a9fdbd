"""ISA's report fragments: the paper's claims, the single vessel, the flow, the study, and its timing fragment."""
