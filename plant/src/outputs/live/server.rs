//! The live view's server: a TCP listener on its own thread and one thread per client, each
//! speaking [`super::protocol`] over a WebSocket (`tungstenite`, blocking, with short socket
//! timeouts so that one thread both reads the client's requests and writes its frames).
//!
//! **Never slowing the run.** The run's side ([`Hub::offer`]) takes the client list with
//! `try_lock` and hands each client a frame with `try_send` on a bounded queue: a busy lock or
//! a full queue drops the frame (counted), nothing waits. A client that reads slowly or never
//! loses frames; its memory is bounded by its queue ([`QUEUE`] frames) and the WebSocket's
//! write buffer ([`MAX_WRITE_BUFFER`]).
//!
//! **Bad clients.** A connection that is not a WebSocket asking for `foxglove.websocket.v1`
//! gets an HTTP error and is closed; text that is not a request of the protocol gets a status
//! message naming what is wrong, and after [`MAX_BAD`] such messages the connection is closed;
//! a message over [`MAX_MESSAGE`] bytes closes it. Subscriptions are one per channel (the
//! protocol's rule), so a flood of them holds at most one per channel. At most [`MAX_CLIENTS`]
//! clients at once: a further connection is closed at once.

use super::protocol::{self, Channel, Level, Request};
use crate::argument::BadArgument;
use std::collections::HashMap;
use std::io::ErrorKind;
use std::net::{SocketAddr, TcpListener, TcpStream, ToSocketAddrs};
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::mpsc::{sync_channel, Receiver, SyncSender, TryRecvError, TrySendError};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};
use tungstenite::protocol::WebSocketConfig;
use tungstenite::{Message, WebSocket};

/// Frames queued per client before new ones are dropped.
pub const QUEUE: usize = 256;
/// Most bytes a client's WebSocket holds unsent before a message is dropped.
pub const MAX_WRITE_BUFFER: usize = 1 << 20;
/// Largest message a client may send (bytes): a subscription request is far smaller.
pub const MAX_MESSAGE: usize = 64 << 10;
/// Messages a client may send that are not requests of the protocol before it is closed.
pub const MAX_BAD: usize = 16;
/// Clients served at once.
pub const MAX_CLIENTS: usize = 8;
/// How long a client's thread waits on its socket before it looks at its queue again.
const POLL: Duration = Duration::from_millis(20);
/// How long a client has for its WebSocket handshake.
const HANDSHAKE: Duration = Duration::from_secs(5);
/// How long the run's end waits for the clients to be sent what was queued for them.
const DRAIN: Duration = Duration::from_secs(2);

/// One frame of the run: messages, each on a channel (its index in the advertised list) at a
/// simulated time (ns).
#[derive(Debug, Default)]
pub struct Frame {
    /// The frame's simulated time (ns), sent as the server's time.
    pub ns: u64,
    /// (channel index, log time in ns, message bytes).
    pub messages: Vec<(usize, u64, Vec<u8>)>,
}

/// What the run hands frames to, and the clients take them from.
#[derive(Default)]
pub struct Hub {
    queues: Mutex<Vec<SyncSender<Arc<Frame>>>>,
    clients: AtomicUsize,
    served: AtomicUsize,
    offered: AtomicU64,
    dropped: AtomicU64,
    done: AtomicBool,
}

impl Hub {
    /// Whether a client is connected (a frame is worth making).
    pub fn has_clients(&self) -> bool {
        self.clients.load(Ordering::Relaxed) > 0
    }

    /// Hands `frame` to each client's queue without waiting: a lock taken or a full queue
    /// drops it for that client.
    pub fn offer(&self, frame: Frame) {
        self.offered.fetch_add(1, Ordering::Relaxed);
        let Ok(mut queues) = self.queues.try_lock() else {
            self.dropped.fetch_add(1, Ordering::Relaxed);
            return;
        };
        let frame = Arc::new(frame);
        queues.retain(|q| match q.try_send(Arc::clone(&frame)) {
            Ok(()) => true,
            Err(TrySendError::Full(_)) => {
                self.dropped.fetch_add(1, Ordering::Relaxed);
                true
            }
            Err(TrySendError::Disconnected(_)) => false,
        });
    }
}

/// What a live run served, for its last line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Served {
    /// Clients that connected (handshake done).
    pub clients: usize,
    /// Frames the run made (while a client was connected).
    pub frames: u64,
    /// Frames not delivered to a client (a full queue, counted per client).
    pub dropped: u64,
}

/// The listening server, bound before the run starts.
pub struct Server {
    addr: SocketAddr,
    hub: Arc<Hub>,
    accept: Option<JoinHandle<()>>,
    threads: Arc<Mutex<Vec<JoinHandle<()>>>>,
}

impl Server {
    /// Binds `addr` (host:port; port 0 lets the system choose) and starts accepting clients,
    /// each welcomed with `info` and the advertisement of `channels`. An address that does not
    /// resolve or cannot be bound (in use, not this host's) is bad input naming it.
    pub fn start(addr: &str, info: String, channels: Vec<Channel>) -> Result<Self, BadArgument> {
        let bad = |why: String| BadArgument(format!("--live {addr}: {why}"));
        let resolved: Vec<SocketAddr> = addr
            .to_socket_addrs()
            .map_err(|e| bad(format!("not an address to listen on (host:port, e.g. 127.0.0.1:8765): {e}")))?
            .collect();
        let listener = TcpListener::bind(&resolved[..]).map_err(|e| bad(format!("cannot listen there: {e}")))?;
        let local = listener.local_addr().map_err(|e| bad(format!("cannot listen there: {e}")))?;
        listener.set_nonblocking(true).map_err(|e| bad(format!("cannot listen there: {e}")))?;
        let hub = Arc::new(Hub::default());
        let threads = Arc::new(Mutex::new(Vec::new()));
        let welcome = Arc::new(Welcome { info, advertise: protocol::advertise(&channels), channels: channels.len() });
        let accept = {
            let (hub, threads) = (Arc::clone(&hub), Arc::clone(&threads));
            std::thread::Builder::new()
                .name("plant-live".into())
                .spawn(move || accept_loop(&listener, &hub, &threads, &welcome))
                .map_err(|e| bad(format!("starting the live view's thread: {e}")))?
        };
        Ok(Self { addr: local, hub, accept: Some(accept), threads })
    }

    /// The address it listens on (the port the system chose for port 0).
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// Where the run hands its frames.
    pub fn hub(&self) -> &Hub {
        &self.hub
    }

    /// Ends the stream: the clients are sent what is queued for them (for at most a bounded
    /// time), then closed; no new client is taken.
    pub fn stop(mut self) -> Served {
        self.hub.done.store(true, Ordering::Relaxed);
        // Dropping the senders lets each client's thread drain its queue, then close.
        self.hub.queues.lock().unwrap_or_else(|e| e.into_inner()).clear();
        if let Some(a) = self.accept.take() {
            let _ = a.join();
        }
        let deadline = Instant::now() + DRAIN;
        let threads = std::mem::take(&mut *self.threads.lock().unwrap_or_else(|e| e.into_inner()));
        for t in threads {
            while !t.is_finished() && Instant::now() < deadline {
                std::thread::sleep(Duration::from_millis(5));
            }
            // A thread still writing to a stuck client after the deadline is left to the
            // process's exit: the run's end never waits on a viewer.
            if t.is_finished() {
                let _ = t.join();
            }
        }
        Served {
            clients: self.hub.served.load(Ordering::Relaxed),
            frames: self.hub.offered.load(Ordering::Relaxed),
            dropped: self.hub.dropped.load(Ordering::Relaxed),
        }
    }
}

/// What each client is sent first.
struct Welcome {
    info: String,
    advertise: String,
    channels: usize,
}

fn accept_loop(
    listener: &TcpListener,
    hub: &Arc<Hub>,
    threads: &Arc<Mutex<Vec<JoinHandle<()>>>>,
    welcome: &Arc<Welcome>,
) {
    while !hub.done.load(Ordering::Relaxed) {
        let stream = match listener.accept() {
            Ok((stream, _)) => stream,
            Err(_) => {
                // Nothing to accept (the listener does not block, so that the run's end stops
                // this loop), or a connection that failed before it was taken.
                std::thread::sleep(POLL);
                continue;
            }
        };
        let mut threads = threads.lock().unwrap_or_else(|e| e.into_inner());
        threads.retain(|t| !t.is_finished());
        if threads.len() >= MAX_CLIENTS {
            continue; // dropping the stream closes it
        }
        let (hub, welcome) = (Arc::clone(hub), Arc::clone(welcome));
        if let Ok(t) =
            std::thread::Builder::new().name("plant-live-client".into()).spawn(move || serve(stream, &hub, &welcome))
        {
            threads.push(t);
        }
    }
}

/// Whether an I/O error is a socket timeout (nothing to read, or the client not reading).
fn timed_out(e: &tungstenite::Error) -> bool {
    matches!(e, tungstenite::Error::Io(io) if matches!(io.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut))
}

/// The WebSocket handshake, selecting the protocol's subprotocol; a client that does not ask
/// for it is refused with an HTTP 400 naming it.
// The callback's error type (an HTTP response) is tungstenite's, not ours to box.
#[allow(clippy::result_large_err)]
fn handshake(stream: TcpStream) -> Option<WebSocket<TcpStream>> {
    stream.set_nodelay(true).ok()?;
    stream.set_read_timeout(Some(HANDSHAKE)).ok()?;
    stream.set_write_timeout(Some(HANDSHAKE)).ok()?;
    let config = WebSocketConfig::default()
        .max_message_size(Some(MAX_MESSAGE))
        .max_frame_size(Some(MAX_MESSAGE))
        .write_buffer_size(64 << 10)
        .max_write_buffer_size(MAX_WRITE_BUFFER);
    let select = |request: &tungstenite::handshake::server::Request,
                  mut response: tungstenite::handshake::server::Response| {
        let offered = request
            .headers()
            .get_all("Sec-WebSocket-Protocol")
            .iter()
            .filter_map(|v| v.to_str().ok())
            .flat_map(|v| v.split(','))
            .any(|p| p.trim() == protocol::SUBPROTOCOL);
        if !offered {
            let body = format!("this server speaks the {} subprotocol only", protocol::SUBPROTOCOL);
            let mut refused = tungstenite::handshake::server::ErrorResponse::new(Some(body));
            *refused.status_mut() = tungstenite::http::StatusCode::BAD_REQUEST;
            return Err(refused);
        }
        let value = tungstenite::http::HeaderValue::from_static(protocol::SUBPROTOCOL);
        response.headers_mut().insert("Sec-WebSocket-Protocol", value);
        Ok(response)
    };
    let ws = tungstenite::accept_hdr_with_config(stream, select, Some(config)).ok()?;
    ws.get_ref().set_read_timeout(Some(POLL)).ok()?;
    ws.get_ref().set_write_timeout(Some(POLL)).ok()?;
    Some(ws)
}

/// One client: welcome, then its requests and its frames until it leaves or the run ends.
fn serve(stream: TcpStream, hub: &Hub, welcome: &Welcome) {
    let Some(mut ws) = handshake(stream) else { return };
    let text = |s: &str| Message::Text(s.to_string().into());
    if ws.send(text(&welcome.info)).is_err() || ws.send(text(&welcome.advertise)).is_err() {
        return;
    }
    let (tx, rx) = sync_channel::<Arc<Frame>>(QUEUE);
    {
        let mut queues = hub.queues.lock().unwrap_or_else(|e| e.into_inner());
        if hub.done.load(Ordering::Relaxed) {
            return;
        }
        queues.push(tx);
    }
    hub.served.fetch_add(1, Ordering::Relaxed);
    hub.clients.fetch_add(1, Ordering::Relaxed);
    let _ = Client { ws: &mut ws, rx: &rx, channels: welcome.channels }.run();
    hub.clients.fetch_sub(1, Ordering::Relaxed);
}

struct Client<'a> {
    ws: &'a mut WebSocket<TcpStream>,
    rx: &'a Receiver<Arc<Frame>>,
    channels: usize,
}

/// Why a client's loop ended (the connection is closed either way).
enum End {
    Gone,
    Done,
}

impl Client<'_> {
    fn run(&mut self) -> End {
        // Subscription id of each channel (one per channel, the protocol's rule).
        let mut by_channel: Vec<Option<u32>> = vec![None; self.channels];
        let mut ids: HashMap<u32, usize> = HashMap::new();
        let mut bad = 0;
        let mut buf = Vec::new();
        loop {
            match self.ws.read() {
                Ok(Message::Text(t)) => match protocol::parse(&t) {
                    Ok(Request::Subscribe(pairs)) => {
                        for (id, channel) in pairs {
                            let index = usize::try_from(channel)
                                .ok()
                                .and_then(|c| c.checked_sub(1))
                                .filter(|&i| i < self.channels);
                            let refused = match index {
                                None => Some(format!("subscribe: no channel {channel}")),
                                Some(_) if ids.contains_key(&id) => {
                                    Some(format!("subscribe: subscription id {id} is in use"))
                                }
                                Some(i) if by_channel[i].is_some() => {
                                    Some(format!("subscribe: channel {channel} is subscribed already"))
                                }
                                Some(i) => {
                                    by_channel[i] = Some(id);
                                    ids.insert(id, i);
                                    None
                                }
                            };
                            if let Some(why) = refused {
                                self.status(Level::Error, &why);
                            }
                        }
                    }
                    Ok(Request::Unsubscribe(list)) => {
                        for id in list {
                            if let Some(i) = ids.remove(&id) {
                                by_channel[i] = None;
                            }
                        }
                    }
                    Ok(Request::Unsupported(op)) => {
                        self.status(Level::Warning, &format!("{op}: not offered by this server"))
                    }
                    Err(why) => {
                        bad += 1;
                        self.status(Level::Error, &why);
                    }
                },
                Ok(Message::Binary(_)) => {
                    bad += 1;
                    self.status(Level::Error, "binary messages from a client are not read (no client publishing)");
                }
                Ok(_) => {}
                Err(e) if timed_out(&e) => {}
                Err(_) => return End::Gone,
            }
            if bad > MAX_BAD {
                let _ = self.ws.close(None);
                let _ = self.ws.flush();
                return End::Gone;
            }
            loop {
                match self.rx.try_recv() {
                    Ok(frame) => {
                        if self.forward(&frame, &by_channel, &mut buf).is_err() {
                            return End::Gone;
                        }
                    }
                    Err(TryRecvError::Empty) => break,
                    Err(TryRecvError::Disconnected) => {
                        // The run ended and everything queued was written.
                        let _ = self.ws.close(None);
                        let deadline = Instant::now() + DRAIN;
                        while self.ws.flush().is_err_and(|e| timed_out(&e)) && Instant::now() < deadline {}
                        return End::Done;
                    }
                }
            }
            match self.ws.flush() {
                Ok(()) => {}
                Err(e) if timed_out(&e) => {}
                Err(_) => return End::Gone,
            }
        }
    }

    /// The frame's time and its messages on the client's subscribed channels; a message the
    /// write buffer has no room for is dropped.
    fn forward(&mut self, frame: &Frame, by_channel: &[Option<u32>], buf: &mut Vec<u8>) -> Result<(), ()> {
        let send = |ws: &mut WebSocket<TcpStream>, bytes: Vec<u8>| match ws.write(Message::Binary(bytes.into())) {
            Ok(()) => Ok(()),
            Err(tungstenite::Error::WriteBufferFull(_)) => Ok(()),
            Err(e) if timed_out(&e) => Ok(()),
            Err(_) => Err(()),
        };
        send(self.ws, protocol::time(frame.ns).to_vec())?;
        for (channel, ns, bytes) in &frame.messages {
            if let Some(sub) = by_channel.get(*channel).copied().flatten() {
                protocol::message_data(sub, *ns, bytes, buf);
                send(self.ws, buf.clone())?;
            }
        }
        Ok(())
    }

    fn status(&mut self, level: Level, message: &str) {
        let _ = self.ws.write(Message::Text(protocol::status(level, message).into()));
    }
}
