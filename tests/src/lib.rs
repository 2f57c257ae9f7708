//! Workspace-level integration tests of primo; the tests live in `tests/`.
