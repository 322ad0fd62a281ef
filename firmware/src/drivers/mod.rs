//! Hardware drivers on embedded-hal 1.0 traits: nothing here knows a vendor HAL.

pub mod as5047p;
pub mod pwm_motor;
