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
mod tests {
    use super::{AllowedHosts, Authority};

    fn at(port: u16, given: &[&str]) -> AllowedHosts {
        let given: Vec<String> = given.iter().map(|s| s.to_string()).collect();
        AllowedHosts::new(([127, 0, 0, 1], port).into(), &given).unwrap()
    }

    #[test]
    fn authorities_parse_with_their_port_or_the_default_one() {
        let a = |name: &str, port| {
            Some(Authority {
                name: name.into(),
                port,
            })
        };
        assert_eq!(Authority::parse("LocalHost:8765", 80), a("localhost", 8765));
        assert_eq!(Authority::parse("viewer.lan", 9000), a("viewer.lan", 9000));
        assert_eq!(Authority::parse("[::1]:8765", 80), a("[::1]", 8765));
        assert_eq!(Authority::parse("[0:0::1]", 80), a("[::1]", 80));
        assert_eq!(Authority::parse("10.0.0.2:1", 80), a("10.0.0.2", 1));
        for refused in [
            "",
            ":8765",
            "localhost:",
            "localhost:port",
            "localhost:65536",
            "localhost:+1",
            "a b:80",
            "user@localhost:80",
            "localhost:80/ws",
            "::1",
            "[::1",
            "[::1]8765",
            "[evil]:80",
            "localhost:80:80",
        ] {
            assert_eq!(Authority::parse(refused, 80), None, "{refused:?}");
        }
    }

    #[test]
    fn only_the_address_s_names_and_the_given_ones_are_answered() {
        let hosts = at(8765, &["Viewer.LAN", "proxy.lan:80"]);
        for accepted in [
            "127.0.0.1:8765",
            "localhost:8765",
            "LOCALHOST:8765",
            "[::1]:8765",
            "viewer.lan:8765",
            "VIEWER.lan:8765",
            "proxy.lan",
            "proxy.lan:80",
        ] {
            assert!(hosts.host(Some(accepted)), "{accepted}");
        }
        for refused in [
            "evil.example:8765",
            "localhost.evil.example:8765",
            "localhost:9999",
            "localhost",
            "127.0.0.1:80",
            "viewer.lan",
            "proxy.lan:8765",
            "127.0.0.1:8765 ",
        ] {
            assert!(!hosts.host(Some(refused)), "{refused}");
        }
        assert!(!hosts.host(None));
        assert_eq!(
            hosts.names(),
            "127.0.0.1:8765, localhost:8765, [::1]:8765, viewer.lan:8765, proxy.lan:80"
        );
    }

    #[test]
    fn another_interface_answers_its_own_address_and_the_names_given_only() {
        let lan = AllowedHosts::new(([192, 168, 1, 5], 80).into(), &[]).unwrap();
        assert!(lan.host(Some("192.168.1.5")) && lan.host(Some("192.168.1.5:80")));
        assert!(!lan.host(Some("localhost:80")) && !lan.host(Some("viewer.lan")));
        let every = AllowedHosts::new(([0, 0, 0, 0], 8765).into(), &["viewer.lan".into()]).unwrap();
        assert!(every.host(Some("0.0.0.0:8765")) && every.host(Some("localhost:8765")));
        assert!(every.host(Some("viewer.lan:8765")) && !every.host(Some("192.168.1.5:8765")));
        let v6 = AllowedHosts::new("[::1]:8765".parse().unwrap(), &[]).unwrap();
        assert_eq!(v6.names(), "[::1]:8765, 127.0.0.1:8765, localhost:8765");
    }

    #[test]
    fn a_name_given_that_is_no_host_is_refused() {
        for bad in [
            "",
            "http://viewer.lan",
            "viewer.lan/",
            "viewer.lan:x",
            "::1",
        ] {
            let e = AllowedHosts::new(([127, 0, 0, 1], 80).into(), &[bad.into()]).unwrap_err();
            assert!(e.to_string().starts_with("invalid allowed host"), "{e}");
        }
    }

    #[test]
    fn a_websocket_s_page_must_be_http_at_a_name_answered() {
        let hosts = at(8765, &["viewer.lan"]);
        for accepted in [
            "http://127.0.0.1:8765",
            "http://localhost:8765",
            "http://[::1]:8765",
            "http://viewer.lan:8765",
        ] {
            assert!(hosts.origin(Some(accepted)), "{accepted}");
        }
        for refused in [
            "http://evil.example:8765",
            "https://localhost:8765",
            "HTTP://localhost:8765x",
            "http://localhost:9999",
            "http://localhost",
            "http://localhost:8765/",
            "localhost:8765",
            "null",
        ] {
            assert!(!hosts.origin(Some(refused)), "{refused}");
        }
        assert!(!hosts.origin(None));
    }
}
