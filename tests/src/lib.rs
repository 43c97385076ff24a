//! Helpers shared by the workspace integration tests (QEMU discovery, firmware builds).
