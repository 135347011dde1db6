//! The names a viewer answers to: its defence against DNS rebinding.
//!
//! A page of any site can point its own name at 127.0.0.1 (DNS rebinding) and then read the
//! viewer's answers as its own origin. Its requests still carry that name in `Host`, so the
//! server answers only the names of the address it listens on and the names it was given
//! ([`AllowedHosts`]); a WebSocket must also come from a page of one of those names
//! (`Origin`). Names compare case-insensitively, ports exactly; a `Host` without a port is at
//! port 80, as a browser omits the default one.

use std::net::{IpAddr, Ipv6Addr, SocketAddr};

use haarshift_relight::{Error, Result};

/// A host name (lower case; an IPv6 address in brackets, in its canonical form) and a port.
#[derive(Clone, Debug, PartialEq, Eq)]
struct Authority {
    name: String,
    port: u16,
}

impl Authority {
    /// `NAME` or `NAME:PORT` (the `Host` header's form), with `default_port` when no port is
    /// given; `None` for anything else (a path, user info, an empty name or port).
    fn parse(text: &str, default_port: u16) -> Option<Authority> {
        let (name, port) = match text.strip_prefix('[') {
            Some(bracketed) => {
                let (address, after) = bracketed.split_once(']')?;
                let address: Ipv6Addr = address.parse().ok()?;
                let port = match after {
                    "" => None,
                    _ => Some(after.strip_prefix(':')?),
                };
                (format!("[{address}]"), port)
            }
            None => {
                let (name, port) = match text.split_once(':') {
                    Some((name, port)) => (name, Some(port)),
                    None => (text, None),
                };
                let plain = |c: char| c.is_ascii_alphanumeric() || matches!(c, '-' | '.' | '_');
                if name.is_empty() || !name.chars().all(plain) {
                    return None;
                }
                (name.to_ascii_lowercase(), port)
            }
        };
        let port = match port {
            None => default_port,
            Some(digits) if !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit()) => {
                digits.parse().ok()?
            }
            Some(_) => return None,
        };
        Some(Authority { name, port })
    }
}

impl std::fmt::Display for Authority {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}", self.name, self.port)
    }
}

/// The `Host`s a viewer answers: the names of its address at its port, and the names given.
#[derive(Clone, Debug)]
pub(crate) struct AllowedHosts {
    accepted: Vec<Authority>,
}

impl AllowedHosts {
    /// The names of `listening` (its own address; on the loopback or every interface also
    /// `127.0.0.1`, `localhost` and `[::1]`), at its port, and each of `given`: `NAME` (at
    /// `listening`'s port) or `NAME:PORT` (another port, as a proxy in front serves it).
    pub(crate) fn new(listening: SocketAddr, given: &[String]) -> Result<AllowedHosts> {
        let port = listening.port();
        let own = match listening.ip() {
            IpAddr::V4(ip) => ip.to_string(),
            IpAddr::V6(ip) => format!("[{ip}]"),
        };
        let mut names = vec![own];
        if listening.ip().is_loopback() || listening.ip().is_unspecified() {
            names.extend(["127.0.0.1", "localhost", "[::1]"].map(String::from));
        }
        let own = names.into_iter().map(|name| Ok(Authority { name, port }));
        let given = given.iter().map(|name| {
            Authority::parse(name, port).ok_or_else(|| {
                Error::parameter(
                    "allowed host",
                    format!(
                        "{name:?}: a host name, an IP address ([IPv6] in brackets) or either \
                         with :PORT is expected"
                    ),
                )
            })
        });
        let mut accepted = Vec::new();
        for authority in own.chain(given) {
            let authority = authority?;
            if !accepted.contains(&authority) {
                accepted.push(authority);
            }
        }
        Ok(AllowedHosts { accepted })
    }

    /// Whether a request with this `Host` header (`None`: none, or more than one) is one the
    /// viewer answers.
    pub(crate) fn host(&self, host: Option<&str>) -> bool {
        host.and_then(|h| Authority::parse(h, 80))
            .is_some_and(|h| self.accepted.contains(&h))
    }

    /// Whether a page at `origin` (the `Origin` header; `None`: none) is the viewer's own:
    /// `http://` and a `Host` it answers.
    pub(crate) fn origin(&self, origin: Option<&str>) -> bool {
        origin
            .and_then(|o| o.strip_prefix("http://"))
            .is_some_and(|authority| self.host(Some(authority)))
    }

    /// The names answered, `NAME:PORT`, for the refusal's message.
    pub(crate) fn names(&self) -> String {
        let names: Vec<String> = self.accepted.iter().map(|a| a.to_string()).collect();
        names.join(", ")
    }
}

#[cfg(test)]
#[path = "host_tests.rs"]
mod tests;
