//! PLACEHOLDER for the Dammertz subdivision kernel.
