//! Reading recordings back (`record/` writes them): any bytes a user names are read
//! into chunks or refused as an unusable file (`read`), and the readers built on it: a
//! recording's rows value by value (`rows`), two recordings compared in step (`compare`), and
//! what `inspect` shows (`inspect`).

mod arrow_message;
pub mod compare;
mod framing;
pub mod inspect;
pub mod read;
mod rows;
#[cfg(test)]
mod tests;
