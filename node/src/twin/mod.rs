//! The twin's rules, apart from any transport: which samples it takes (the gate), how far the
//! solver may run (the pacer, on the node's clock), the gauges' readings, the settings, and
//! the messages its observations become.

pub mod clock;
pub mod gate;
pub mod messages;
pub mod pacer;
pub mod samples;
pub mod settings;
pub mod solver_thread;
pub mod visual;
