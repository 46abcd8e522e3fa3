//! Parses the URLs that choose a transport: `swarmcon://HOST:PORT`, `udp://HOST:PORT`,
//! `replay://FILE[?speed=S|max]` for pose sources; `serial://DEVICE[?baud=N]`,
//! `udp://HOST:PORT[?baud=N]` for robot links.

use crate::protocol::colias::DEFAULT_BAUD;
use crate::protocol::swarmcon::DEFAULT_PORT;
use std::path::PathBuf;
use thiserror::Error;

#[derive(Clone, Debug, Error, PartialEq)]
pub enum UrlError {
    #[error("`{url}`: expected SCHEME://..., one of {expected}")]
    NoScheme { url: String, expected: &'static str },
    #[error("`{url}`: unknown scheme `{scheme}`, expected one of {expected}")]
    Scheme {
        url: String,
        scheme: String,
        expected: &'static str,
    },
    #[error("`{url}`: {what} is missing")]
    Missing { url: String, what: &'static str },
    #[error("`{url}`: port `{port}` is not a number from 1 to 65535")]
    Port { url: String, port: String },
    #[error("`{url}`: `{key}={value}`: {reason}")]
    Query {
        url: String,
        key: String,
        value: String,
        reason: &'static str,
    },
    #[error("`{url}`: unknown option `{key}`, expected {expected}")]
    UnknownKey {
        url: String,
        key: String,
        expected: &'static str,
    },
}

/// Where poses come from.
#[derive(Clone, Debug, PartialEq)]
pub enum PoseUrl {
    /// A SwarmCon / CosPhi position server to connect to.
    SwarmCon { host: String, port: u16 },
    /// A local address to bind and receive JSON pose datagrams on.
    Udp { host: String, port: u16 },
    /// A recorded file; `speed` 1 is recorded speed, `None` as fast as possible.
    Replay { path: PathBuf, speed: Option<f64> },
}

/// Where robot commands go and telemetry comes from.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum LinkUrl {
    Serial {
        device: String,
        baud: u32,
    },
    /// A twin or radio bridge over UDP; `baud` sets the emulated channel's airtime.
    Udp {
        host: String,
        port: u16,
        baud: u32,
    },
}

struct Parts<'a> {
    url: &'a str,
    scheme: &'a str,
    rest: &'a str,
    query: Vec<(&'a str, &'a str)>,
}

fn split<'a>(url: &'a str, expected: &'static str) -> Result<Parts<'a>, UrlError> {
    let (scheme, after) = url.split_once("://").ok_or_else(|| UrlError::NoScheme {
        url: url.into(),
        expected,
    })?;
    let (rest, query) = match after.split_once('?') {
        Some((r, q)) => (r, q),
        None => (after, ""),
    };
    let mut pairs = Vec::new();
    for kv in query.split('&').filter(|s| !s.is_empty()) {
        let (k, v) = kv.split_once('=').unwrap_or((kv, ""));
        pairs.push((k, v));
    }
    Ok(Parts {
        url,
        scheme,
        rest,
        query: pairs,
    })
}

fn host_port(p: &Parts<'_>, default_port: Option<u16>) -> Result<(String, u16), UrlError> {
    let missing = |what| UrlError::Missing {
        url: p.url.into(),
        what,
    };
    let rest = p.rest.trim_end_matches('/');
    // `[::1]:6666` keeps its brackets out of the host.
    let (host, port) = if let Some(r) = rest.strip_prefix('[') {
        let (h, tail) = r.split_once(']').ok_or_else(|| missing("closing `]`"))?;
        (h, tail.strip_prefix(':'))
    } else {
        match rest.rsplit_once(':') {
            Some((h, port)) => (h, Some(port)),
            None => (rest, None),
        }
    };
    if host.is_empty() {
        return Err(missing("host"));
    }
    let port = match (port, default_port) {
        (Some(s), _) => match s.parse::<u16>() {
            Ok(n) if n > 0 => n,
            _ => {
                return Err(UrlError::Port {
                    url: p.url.into(),
                    port: s.into(),
                });
            }
        },
        (None, Some(d)) => d,
        (None, None) => return Err(missing("port")),
    };
    Ok((host.to_string(), port))
}

fn only_keys(p: &Parts<'_>, allowed: &[&str], expected: &'static str) -> Result<(), UrlError> {
    match p.query.iter().find(|(k, _)| !allowed.contains(k)) {
        Some((k, _)) => Err(UrlError::UnknownKey {
            url: p.url.into(),
            key: (*k).into(),
            expected,
        }),
        None => Ok(()),
    }
}

/// The query option `key` through `parse` (`None` when the URL has no such option); a value `parse`
/// refuses is an error that gives `reason`.
fn query_option<T>(
    p: &Parts<'_>,
    key: &str,
    reason: &'static str,
    parse: impl Fn(&str) -> Option<T>,
) -> Result<Option<T>, UrlError> {
    let Some((k, v)) = p.query.iter().find(|(k, _)| *k == key) else {
        return Ok(None);
    };
    match parse(v) {
        Some(x) => Ok(Some(x)),
        None => Err(UrlError::Query {
            url: p.url.into(),
            key: (*k).into(),
            value: (*v).into(),
            reason,
        }),
    }
}

fn baud(p: &Parts<'_>) -> Result<u32, UrlError> {
    only_keys(p, &["baud"], "`baud`")?;
    let baud = query_option(p, "baud", "must be a baud rate from 300 to 10000000", |v| {
        v.parse::<u32>()
            .ok()
            .filter(|b| (300..=10_000_000).contains(b))
    })?;
    Ok(baud.unwrap_or(DEFAULT_BAUD))
}

impl std::str::FromStr for PoseUrl {
    type Err = UrlError;

    fn from_str(url: &str) -> Result<Self, UrlError> {
        const EXPECTED: &str = "swarmcon://, udp://, replay://";
        let p = split(url, EXPECTED)?;
        match p.scheme {
            "swarmcon" => {
                only_keys(&p, &[], "none")?;
                let (host, port) = host_port(&p, Some(DEFAULT_PORT))?;
                Ok(PoseUrl::SwarmCon { host, port })
            }
            "udp" => {
                only_keys(&p, &[], "none")?;
                let (host, port) = host_port(&p, None)?;
                Ok(PoseUrl::Udp { host, port })
            }
            "replay" => {
                only_keys(&p, &["speed"], "`speed`")?;
                if p.rest.is_empty() {
                    return Err(UrlError::Missing {
                        url: url.into(),
                        what: "file",
                    });
                }
                // `max`: as fast as possible (no factor); absent: recorded speed (1).
                let factor = |v: &str| match v {
                    "max" => Some(None),
                    s => s
                        .parse::<f64>()
                        .ok()
                        .filter(|x| x.is_finite() && *x > 0.0)
                        .map(Some),
                };
                let speed =
                    query_option(&p, "speed", "must be a positive factor or `max`", factor)?;
                Ok(PoseUrl::Replay {
                    path: PathBuf::from(p.rest),
                    speed: speed.unwrap_or(Some(1.0)),
                })
            }
            other => Err(UrlError::Scheme {
                url: url.into(),
                scheme: other.into(),
                expected: EXPECTED,
            }),
        }
    }
}

impl std::str::FromStr for LinkUrl {
    type Err = UrlError;

    fn from_str(url: &str) -> Result<Self, UrlError> {
        const EXPECTED: &str = "serial://, udp://";
        let p = split(url, EXPECTED)?;
        match p.scheme {
            "serial" => {
                let baud = baud(&p)?;
                if p.rest.is_empty() {
                    return Err(UrlError::Missing {
                        url: url.into(),
                        what: "device",
                    });
                }
                Ok(LinkUrl::Serial {
                    device: p.rest.into(),
                    baud,
                })
            }
            "udp" => {
                let baud = baud(&p)?;
                let (host, port) = host_port(&p, None)?;
                Ok(LinkUrl::Udp { host, port, baud })
            }
            other => Err(UrlError::Scheme {
                url: url.into(),
                scheme: other.into(),
                expected: EXPECTED,
            }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pose_urls() {
        assert_eq!(
            "swarmcon://192.168.1.5".parse::<PoseUrl>().unwrap(),
            PoseUrl::SwarmCon {
                host: "192.168.1.5".into(),
                port: 6666
            }
        );
        assert_eq!(
            "udp://[::1]:9000".parse::<PoseUrl>().unwrap(),
            PoseUrl::Udp {
                host: "::1".into(),
                port: 9000
            }
        );
        assert_eq!(
            "replay:///tmp/log.txt?speed=max"
                .parse::<PoseUrl>()
                .unwrap(),
            PoseUrl::Replay {
                path: "/tmp/log.txt".into(),
                speed: None
            }
        );
        let e = |s: &str| s.parse::<PoseUrl>().unwrap_err().to_string();
        assert!(e("tcp://x:1").contains("unknown scheme `tcp`"));
        assert!(e("udp://x").contains("port is missing"));
        assert!(e("swarmcon://x:99999").contains("port `99999`"));
        assert!(e("replay://f?speed=-1").contains("speed=-1"));
        assert!(e("replay://f?rate=2").contains("unknown option `rate`"));
        assert!(e("localhost:6666").contains("SCHEME://"));
    }

    #[test]
    fn link_urls() {
        assert_eq!(
            "serial:///dev/ttyUSB0?baud=57600"
                .parse::<LinkUrl>()
                .unwrap(),
            LinkUrl::Serial {
                device: "/dev/ttyUSB0".into(),
                baud: 57600
            }
        );
        assert_eq!(
            "udp://127.0.0.1:7000".parse::<LinkUrl>().unwrap(),
            LinkUrl::Udp {
                host: "127.0.0.1".into(),
                port: 7000,
                baud: 115_200
            }
        );
        assert!(
            "serial:///dev/ttyUSB0?baud=fast"
                .parse::<LinkUrl>()
                .unwrap_err()
                .to_string()
                .contains("baud=fast")
        );
    }
}
