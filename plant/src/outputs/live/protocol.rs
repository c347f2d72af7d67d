//! The Foxglove WebSocket protocol (`foxglove.websocket.v1`), the part a server of logged
//! topics speaks: the JSON messages it sends (server info, advertise, status), the client's
//! (subscribe, unsubscribe) parsed, and the binary frames (message data, time). Pure: text and
//! bytes in and out; the sockets are [`super::server`]'s.
//!
//! Written here rather than taken from the `foxglove` crate: see [`super`] for why. The
//! protocol's document is `docs/spec.md` of the `foxglove/ws-protocol` repository.

use serde_json::{json, Value};

/// The WebSocket subprotocol a client asks for and the server selects.
pub const SUBPROTOCOL: &str = "foxglove.websocket.v1";

/// The binary opcode of a message's data (server to client).
pub const OP_MESSAGE_DATA: u8 = 0x01;

/// The binary opcode of the server's time (server to client; the `time` capability).
pub const OP_TIME: u8 = 0x02;

/// One advertised channel.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Channel {
    /// The channel's id (the server's choice).
    pub id: u32,
    /// The topic (`/plane_a/rotor`, …).
    pub topic: String,
    /// The messages' encoding (`cdr`, `json`).
    pub encoding: &'static str,
    /// The schema's name (`plant_msgs/msg/Rotor`, `foxglove.Log`).
    pub schema_name: String,
    /// The schema's text.
    pub schema: String,
    /// The schema's encoding (`ros2msg`, `jsonschema`).
    pub schema_encoding: &'static str,
}

/// The server info sent first to each client: its name, the `time` capability (the server
/// sends the simulated time), and the scene's name as metadata.
pub fn server_info(name: &str, scene: &str, session: &str) -> String {
    json!({
        "op": "serverInfo",
        "name": name,
        "capabilities": ["time"],
        "metadata": {"scene": scene},
        "sessionId": session,
    })
    .to_string()
}

/// The advertisement of `channels`.
pub fn advertise(channels: &[Channel]) -> String {
    let channels: Vec<Value> = channels
        .iter()
        .map(|c| {
            json!({
                "id": c.id,
                "topic": c.topic,
                "encoding": c.encoding,
                "schemaName": c.schema_name,
                "schema": c.schema,
                "schemaEncoding": c.schema_encoding,
            })
        })
        .collect();
    json!({"op": "advertise", "channels": channels}).to_string()
}

/// A status message's level.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Level {
    /// 0.
    Info = 0,
    /// 1.
    Warning = 1,
    /// 2.
    Error = 2,
}

/// A status message for the client (a viewer shows it).
pub fn status(level: Level, message: &str) -> String {
    json!({"op": "status", "level": level as u8, "message": message}).to_string()
}

/// What a client asked for.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Request {
    /// `subscribe`: (subscription id, channel id) pairs.
    Subscribe(Vec<(u32, u32)>),
    /// `unsubscribe`: subscription ids.
    Unsubscribe(Vec<u32>),
    /// Another operation of the protocol this server does not offer (parameters, services,
    /// client publishing): named, ignored.
    Unsupported(String),
}

/// A client's text message, or why it is not one this server reads (not JSON, no `op`, a
/// field missing or not a 32-bit id).
pub fn parse(text: &str) -> Result<Request, String> {
    let value: Value = serde_json::from_str(text).map_err(|e| format!("not JSON: {e}"))?;
    let op = value.get("op").and_then(Value::as_str).ok_or("no \"op\" string")?;
    let id = |v: &Value, key: &str| -> Result<u32, String> {
        v.get(key)
            .and_then(Value::as_u64)
            .and_then(|n| u32::try_from(n).ok())
            .ok_or_else(|| format!("{op}: \"{key}\" is not a 32-bit id"))
    };
    let array = |key: &str| -> Result<&Vec<Value>, String> {
        value.get(key).and_then(Value::as_array).ok_or_else(|| format!("{op}: no \"{key}\" array"))
    };
    match op {
        "subscribe" => {
            let pairs = array("subscriptions")?;
            pairs
                .iter()
                .map(|s| Ok((id(s, "id")?, id(s, "channelId")?)))
                .collect::<Result<_, String>>()
                .map(Request::Subscribe)
        }
        "unsubscribe" => {
            let ids = array("subscriptionIds")?;
            ids.iter()
                .map(|v| {
                    v.as_u64()
                        .and_then(|n| u32::try_from(n).ok())
                        .ok_or_else(|| format!("{op}: an id is not a 32-bit id"))
                })
                .collect::<Result<_, String>>()
                .map(Request::Unsubscribe)
        }
        other => Ok(Request::Unsupported(other.to_string())),
    }
}

/// A message's data frame into `out` (cleared first): the opcode, the subscription's id
/// (u32, little-endian), the log time (u64 ns, little-endian), the message's bytes.
pub fn message_data(subscription: u32, ns: u64, payload: &[u8], out: &mut Vec<u8>) {
    out.clear();
    out.push(OP_MESSAGE_DATA);
    out.extend_from_slice(&subscription.to_le_bytes());
    out.extend_from_slice(&ns.to_le_bytes());
    out.extend_from_slice(payload);
}

/// A time frame: the opcode and the time (u64 ns, little-endian).
pub fn time(ns: u64) -> [u8; 9] {
    let mut out = [0u8; 9];
    out[0] = OP_TIME;
    out[1..].copy_from_slice(&ns.to_le_bytes());
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_message_data_frame_is_opcode_subscription_time_payload() {
        let mut out = Vec::new();
        message_data(0x0102_0304, 0x1122_3344_5566_7788, &[9, 8], &mut out);
        assert_eq!(out, [1, 4, 3, 2, 1, 0x88, 0x77, 0x66, 0x55, 0x44, 0x33, 0x22, 0x11, 9, 8]);
        assert_eq!(time(1), [2, 1, 0, 0, 0, 0, 0, 0, 0]);
    }

    #[test]
    fn the_clients_requests_are_read_and_garbage_is_named() {
        let sub = parse(r#"{"op":"subscribe","subscriptions":[{"id":0,"channelId":3},{"id":1,"channelId":5}]}"#);
        assert_eq!(sub, Ok(Request::Subscribe(vec![(0, 3), (1, 5)])));
        assert_eq!(parse(r#"{"op":"unsubscribe","subscriptionIds":[0,1]}"#), Ok(Request::Unsubscribe(vec![0, 1])));
        assert_eq!(
            parse(r#"{"op":"getParameters","parameterNames":[]}"#),
            Ok(Request::Unsupported("getParameters".into()))
        );
        assert!(parse("hello").unwrap_err().starts_with("not JSON"));
        assert_eq!(parse(r#"{"x":1}"#).unwrap_err(), "no \"op\" string");
        assert_eq!(parse(r#"{"op":"subscribe"}"#).unwrap_err(), "subscribe: no \"subscriptions\" array");
        let big = parse(r#"{"op":"subscribe","subscriptions":[{"id":4294967296,"channelId":1}]}"#);
        assert_eq!(big.unwrap_err(), "subscribe: \"id\" is not a 32-bit id");
        assert!(parse(r#"{"op":"unsubscribe","subscriptionIds":[-1]}"#).is_err());
    }

    #[test]
    fn the_advertisement_names_each_channels_fields_as_the_spec_does() {
        let c = Channel {
            id: 7,
            topic: "/t".into(),
            encoding: "cdr",
            schema_name: "p_msgs/msg/T".into(),
            schema: "float64 x\n".into(),
            schema_encoding: "ros2msg",
        };
        let v: Value = serde_json::from_str(&advertise(&[c])).unwrap();
        assert_eq!(v["op"], "advertise");
        let ch = &v["channels"][0];
        assert_eq!((ch["id"].as_u64(), ch["topic"].as_str()), (Some(7), Some("/t")));
        assert_eq!((ch["encoding"].as_str(), ch["schemaEncoding"].as_str()), (Some("cdr"), Some("ros2msg")));
        assert_eq!((ch["schemaName"].as_str(), ch["schema"].as_str()), (Some("p_msgs/msg/T"), Some("float64 x\n")));
        let info: Value = serde_json::from_str(&server_info("plant", "s", "1")).unwrap();
        assert_eq!(info["op"], "serverInfo");
        assert_eq!(info["capabilities"][0], "time");
        let st: Value = serde_json::from_str(&status(Level::Warning, "m")).unwrap();
        assert_eq!((st["op"].as_str(), st["level"].as_u64()), (Some("status"), Some(1)));
    }
}
