//! A peer of protocol version 3 as iceoryx2 sees it: the v3 `Hello` and `Ack` under their v3
//! type names and sizes (4312 and 4416 bytes), for the tests of what a version-4 plant or
//! controller says when it meets one. Only the services matter: the payloads are never sent.
// Each test binary that includes this uses a part of it.
#![allow(dead_code)]

use controller::link::{self, Ipc, Mailbox};
use iceoryx2::prelude::ZeroCopySend;

/// Protocol 3's `Hello` (its type name and size).
#[derive(Debug, Clone, Copy, ZeroCopySend)]
#[type_name("amb_testbed.v3.Hello")]
#[repr(C)]
pub struct Hello {
    bytes: [u64; 4312 / 8],
}

/// Protocol 3's `Ack` (its type name and size).
#[derive(Debug, Clone, Copy, ZeroCopySend)]
#[type_name("amb_testbed.v3.Ack")]
#[repr(C)]
pub struct Ack {
    bytes: [u64; 4416 / 8],
}

/// The handshake services of run `id` as a version-3 peer opens them, held while it lives.
pub struct Peer {
    _plant: Option<Mailbox<Hello, Ack>>,
    _controller: Option<Mailbox<Ack, Hello>>,
    _node: iceoryx2::node::Node<Ipc>,
}

impl Peer {
    /// A version-3 plant: it publishes `hello` and reads `ack`.
    pub fn plant(id: &str) -> Self {
        let node = link::node(id, "plant").expect("node");
        let mailbox = Mailbox::open(&node, id, "hello", "ack").expect("v3 services");
        Self { _plant: Some(mailbox), _controller: None, _node: node }
    }

    /// A version-3 controller: it publishes `ack` and reads `hello`.
    pub fn controller(id: &str) -> Self {
        let node = link::node(id, "controller").expect("node");
        let mailbox = Mailbox::open(&node, id, "ack", "hello").expect("v3 services");
        Self { _plant: None, _controller: Some(mailbox), _node: node }
    }
}
