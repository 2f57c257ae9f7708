//! Each device's endpoint: what it accepts and what it answers. The
//! learning coprocessor serves [`Learner`]; the scale serves [`Scale`],
//! the learner's messages and the scale's.
//!
//! | Endpoint    | Request                   | Reply                   | Device                   |
//! |-------------|---------------------------|-------------------------|--------------------------|
//! | [`Learner`] | [`learner::Request`]      | [`learner::Reply`]      | the learning coprocessor |
//! | [`Scale`]   | [`scale::Request`]        | [`scale::Reply`]        | the scale                |
//!
//! The scale also sends [`scale::Reply`]s unasked, numbered
//! [`scale::STREAM`] (its stream of readings).

use serde::Serialize;
use serde::de::DeserializeOwned;

use crate::fault::Fault;
use crate::{learner, scale};

/// A device's endpoint: the requests it accepts and the replies it
/// answers them with. Every reply can say that a request failed.
pub trait Endpoint {
    /// What the device accepts.
    type Request: Serialize + DeserializeOwned;
    /// What it answers.
    type Reply: Serialize + DeserializeOwned + From<Fault>;
}

/// The learning coprocessor's endpoint: the learner's messages alone.
#[derive(Debug, Clone, Copy)]
pub enum Learner {}

impl Endpoint for Learner {
    type Request = learner::Request;
    type Reply = learner::Reply;
}

/// The scale's endpoint: the learner's messages and the scale's.
#[derive(Debug, Clone, Copy)]
pub enum Scale {}

impl Endpoint for Scale {
    type Request = scale::Request;
    type Reply = scale::Reply;
}
