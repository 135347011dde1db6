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
