//! Two- and four-position north seeking as a non-blocking state machine.
