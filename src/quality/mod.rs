//! Volume-mesh checker: the oracle every test uses (to be written).
