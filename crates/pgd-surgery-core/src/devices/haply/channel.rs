//! The connection to the Inverse Service: its address, its version over HTTP, and the
//! simulation channel's WebSocket, one message out and one frame back per exchange.

use std::io::{ErrorKind, Read, Write};
use std::net::{SocketAddr, TcpStream, ToSocketAddrs};
use std::time::{Duration, Instant};

use tungstenite::protocol::WebSocket;
use tungstenite::{Message, Utf8Bytes};

use super::wire::WireFormat;

/// Where the service listens unless told otherwise (Haply's default simulation channel).
pub const DEFAULT_URL: &str = "ws://localhost:10001";

/// How long connecting, or a reply to the HTTP version request, may take.
const CONNECT_WITHIN: Duration = Duration::from_millis(500);

/// The service's address, from a `ws://HOST[:PORT][/PATH]` URL.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ServiceUrl {
    pub host: String,
    pub port: u16,
    pub path: String,
}

impl ServiceUrl {
    /// `url` read, or why it is not a service's address.
    pub fn parse(url: &str) -> Result<Self, String> {
        let Some(rest) = url.strip_prefix("ws://") else {
            return Err(format!(
                "`{url}` is not a WebSocket address: the Haply Inverse Service's is \
                 ws://HOST:PORT, by default {DEFAULT_URL} (TLS, wss://, is not spoken: the \
                 service runs on this machine)"
            ));
        };
        let (authority, path) = match rest.find('/') {
            Some(k) => (&rest[..k], &rest[k..]),
            None => (rest, "/"),
        };
        let (host, port) = match authority.rsplit_once(':') {
            Some((host, port)) => (
                host,
                port.parse::<u16>()
                    .map_err(|_| format!("`{url}`: `{port}` is not a port (1 to 65535)"))?,
            ),
            None => (authority, 10001),
        };
        if host.is_empty() || port == 0 {
            return Err(format!("`{url}`: no host, or port 0"));
        }
        Ok(Self {
            host: host.to_owned(),
            port,
            path: path.to_owned(),
        })
    }

    /// The URL as written for people and for the WebSocket handshake.
    pub fn ws(&self) -> String {
        format!("ws://{}:{}{}", self.host, self.port, self.path)
    }

    fn socket_addr(&self) -> std::io::Result<SocketAddr> {
        (self.host.as_str(), self.port)
            .to_socket_addrs()?
            .next()
            .ok_or_else(|| std::io::Error::new(ErrorKind::NotFound, "the host has no address"))
    }

    /// A TCP connection to the service, within [`CONNECT_WITHIN`], without Nagle's delay.
    fn connect(&self) -> std::io::Result<TcpStream> {
        let stream = TcpStream::connect_timeout(&self.socket_addr()?, CONNECT_WITHIN)?;
        stream.set_nodelay(true)?;
        Ok(stream)
    }

    /// The version the service states at `GET /version` (its `project_version`, else its
    /// `git_tag`), or why it could not be had.
    pub fn version(&self) -> Result<String, std::io::Error> {
        let mut stream = self.connect()?;
        stream.set_read_timeout(Some(CONNECT_WITHIN))?;
        let request = format!(
            "GET /version HTTP/1.1\r\nHost: {}:{}\r\nAccept: application/json\r\n\
             Connection: close\r\n\r\n",
            self.host, self.port
        );
        stream.write_all(request.as_bytes())?;
        let mut reply = Vec::new();
        stream.read_to_end(&mut reply)?;
        version_of(&reply).ok_or_else(|| {
            std::io::Error::new(ErrorKind::InvalidData, "GET /version gave no version")
        })
    }
}

/// The version in an HTTP reply to `GET /version`; a 3.5 service may wrap it in `{ok, data}`.
fn version_of(reply: &[u8]) -> Option<String> {
    let mut headers = [httparse::EMPTY_HEADER; 32];
    let mut response = httparse::Response::new(&mut headers);
    let httparse::Status::Complete(body_at) = response.parse(reply).ok()? else {
        return None;
    };
    if response.code != Some(200) {
        return None;
    }
    let body: serde_json::Value = serde_json::from_slice(&reply[body_at..]).ok()?;
    let fields = body.get("data").unwrap_or(&body);
    ["project_version", "git_tag"]
        .iter()
        .find_map(|name| fields.get(name)?.as_str().map(str::to_owned))
}

/// The wire format for a service that states `version`, with a warning when the version says
/// nothing the client knows (the current format, 3.5's, is then assumed).
pub fn format_for(version: Result<String, std::io::Error>) -> (WireFormat, Option<String>) {
    let stated = match version {
        Ok(version) => version,
        Err(e) => {
            let warning = format!(
                "warning: the Haply Inverse Service did not state its version ({e}); speaking \
                 its 3.5 format"
            );
            return (WireFormat::Vector, Some(warning));
        }
    };
    match WireFormat::of_version(&stated) {
        Some(format) => (format, None),
        None => (
            WireFormat::Vector,
            Some(format!(
                "warning: the Haply Inverse Service states version `{stated}`, which this \
                 trainer does not know (3.1 or later is spoken); speaking its 3.5 format"
            )),
        ),
    }
}

/// Why an exchange failed.
#[derive(Debug)]
pub enum ExchangeError {
    /// No reply within the wait given; the connection may still answer.
    Late,
    /// The connection is gone (closed, reset, a protocol error).
    Lost(String),
}

/// The simulation channel: a WebSocket session with the service.
pub struct Channel {
    socket: WebSocket<TcpStream>,
}

impl Channel {
    /// Connects and completes the WebSocket handshake.
    pub fn open(url: &ServiceUrl) -> Result<Self, String> {
        let stream = url.connect().map_err(|e| e.to_string())?;
        stream
            .set_read_timeout(Some(CONNECT_WITHIN))
            .map_err(|e| e.to_string())?;
        let (socket, _) = tungstenite::client(url.ws(), stream)
            .map_err(|e| format!("the WebSocket handshake failed: {e}"))?;
        Ok(Self { socket })
    }

    /// Sends one message.
    pub fn send(&mut self, text: String) -> Result<(), ExchangeError> {
        self.socket
            .send(Message::Text(Utf8Bytes::from(text)))
            .map_err(lost)
    }

    /// The next text frame, waiting up to `wait`. Frames of another kind are skipped, each
    /// counted in `skipped` (pings are answered by the WebSocket layer).
    pub fn receive(&mut self, wait: Duration, skipped: &mut u64) -> Result<String, ExchangeError> {
        let give_up = Instant::now() + wait;
        loop {
            let left = give_up.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return Err(ExchangeError::Late);
            }
            let timeout = self.socket.get_ref().set_read_timeout(Some(left));
            timeout.map_err(|e| ExchangeError::Lost(e.to_string()))?;
            match self.socket.read() {
                Ok(Message::Text(text)) => return Ok(text.as_str().to_owned()),
                Ok(Message::Close(_)) => {
                    return Err(ExchangeError::Lost(
                        "the service closed the connection".into(),
                    ));
                }
                Ok(Message::Binary(_)) => *skipped += 1,
                Ok(_) => {}
                Err(tungstenite::Error::Io(e)) if timed_out(&e) => {}
                Err(e) => return Err(lost(e)),
            }
        }
    }

    /// Closes the session: a close frame, and the service's answer awaited briefly.
    pub fn close(mut self) {
        if self.socket.close(None).is_err() {
            return;
        }
        let give_up = Instant::now() + CLOSE_WITHIN;
        let _ = (self.socket.get_ref()).set_read_timeout(Some(Duration::from_millis(10)));
        while Instant::now() < give_up {
            match self.socket.read() {
                Ok(_) => {}
                Err(tungstenite::Error::Io(e)) if timed_out(&e) => {}
                Err(_) => return,
            }
        }
    }
}

/// How long closing waits for the service's close frame.
const CLOSE_WITHIN: Duration = Duration::from_millis(100);

/// Whether a read ended for want of data within its timeout, not for a fault.
fn timed_out(e: &std::io::Error) -> bool {
    matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut)
}

fn lost(e: tungstenite::Error) -> ExchangeError {
    ExchangeError::Lost(match e {
        tungstenite::Error::ConnectionClosed | tungstenite::Error::AlreadyClosed => {
            "the connection was closed".into()
        }
        e => e.to_string(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_service_url_is_read_or_refused() {
        let url = ServiceUrl::parse("ws://127.0.0.1:4242").unwrap();
        assert_eq!(
            (url.host.as_str(), url.port, url.path.as_str()),
            ("127.0.0.1", 4242, "/")
        );
        assert_eq!(ServiceUrl::parse(DEFAULT_URL).unwrap().port, 10001);
        assert_eq!(
            ServiceUrl::parse("ws://host/x").unwrap().ws(),
            "ws://host:10001/x"
        );
        for bad in [
            "http://localhost:10001",
            "wss://localhost",
            "ws://:10",
            "ws://h:port",
            "ws://h:0",
        ] {
            assert!(ServiceUrl::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn the_version_is_read_from_either_reply() {
        let plain = b"HTTP/1.1 200 OK\r\nContent-Type: application/json\r\n\r\n\
            {\"project_version\": \"3.4.1.0\", \"git_tag\": \"3.4.1\"}";
        assert_eq!(version_of(plain).as_deref(), Some("3.4.1.0"));
        let wrapped = b"HTTP/1.1 200 OK\r\n\r\n{\"ok\": true, \"data\": {\"git_tag\": \"3.5.0\"}}";
        assert_eq!(version_of(wrapped).as_deref(), Some("3.5.0"));
        assert_eq!(version_of(b"HTTP/1.1 404 Not Found\r\n\r\n{}"), None);
    }
}
