#include "edm/hmi/web_capabilities.hpp"

#include <algorithm>
#include <boost/asio/connect.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/read_until.hpp>
#include <boost/asio/streambuf.hpp>
#include <boost/asio/write.hpp>
#include <functional>
#include <istream>
#include <stdexcept>

namespace edm::hmi {

namespace asio = boost::asio;
using bridge::Json;

std::vector<std::string> probe_ops(const std::string& host, std::uint16_t port,
                                   const std::vector<std::string>& ops,
                                   std::chrono::milliseconds timeout) {
  asio::io_context ioc;
  asio::ip::tcp::socket socket(ioc);
  asio::ip::tcp::resolver resolver(ioc);
  std::string requests;
  for (std::size_t i = 0; i < ops.size(); ++i) {
    // No hello: nothing but unknown_op / unauthorized can come back.
    requests += Json{{"id", i + 1}, {"op", ops[i]}}.dump() + "\n";
  }
  asio::streambuf in;
  std::vector<std::string> known;
  std::string failure;
  std::size_t replies = 0;
  std::function<void()> read_next = [&] {
    asio::async_read_until(socket, in, '\n', [&](boost::system::error_code ec, std::size_t) {
      if (ec) {
        failure = "read: " + ec.message();
        return;
      }
      std::istream is(&in);
      std::string line;
      std::getline(is, line);
      const Json j = Json::parse(line, nullptr, /*allow_exceptions=*/false);
      if (j.is_object() && j.contains("id") && j["id"].is_number_unsigned()) {
        const auto id = j["id"].get<std::size_t>();
        const bool unknown = j.contains("error") && j["error"].is_object() &&
                             j["error"].value("code", std::string()) == "unknown_op";
        if (id >= 1 && id <= ops.size() && !unknown) known.push_back(ops[id - 1]);
        ++replies;
      }
      if (replies < ops.size()) read_next();
    });
  };
  resolver.async_resolve(host, std::to_string(port), [&](boost::system::error_code ec, auto eps) {
    if (ec) {
      failure = "resolve: " + ec.message();
      return;
    }
    asio::async_connect(socket, eps, [&](boost::system::error_code ec2, const auto&) {
      if (ec2) {
        failure = "connect: " + ec2.message();
        return;
      }
      asio::async_write(socket, asio::buffer(requests),
                        [&](boost::system::error_code ec3, std::size_t) {
                          if (ec3) {
                            failure = "write: " + ec3.message();
                            return;
                          }
                          read_next();
                        });
    });
  });
  ioc.run_for(timeout);
  if (!failure.empty()) throw std::runtime_error("capability probe: " + failure);
  if (replies < ops.size()) throw std::runtime_error("capability probe: no reply in time");
  return known;
}

std::vector<std::string> operator_function_ops() {
  std::vector<std::string> ops;
  for (const OperatorFunction& f : kOperatorFunctions) {
    if (std::find(ops.begin(), ops.end(), f.op) == ops.end()) ops.emplace_back(f.op);
  }
  return ops;
}

Json capabilities_json(const Json& machine_info, const std::vector<std::string>* probed) {
  std::vector<std::string> ops;
  std::string source = "none";
  if (machine_info.is_object() && machine_info.contains("ops") && machine_info["ops"].is_array()) {
    source = "machine.info";
    for (const Json& o : machine_info["ops"]) {
      if (o.is_string()) ops.push_back(o.get<std::string>());
    }
  } else if (probed != nullptr) {
    source = "probe";
    ops = *probed;
  }
  const auto has = [&ops](std::string_view op) {
    return std::find(ops.begin(), ops.end(), op) != ops.end();
  };
  Json manual = nullptr;
  if (machine_info.is_object() && machine_info.contains("manual") &&
      machine_info["manual"].is_object()) {
    manual = machine_info["manual"];
  }
  Json caps = {{"source", source}, {"manual", manual}};
  Json why = Json::object();
  for (const OperatorFunction& f : kOperatorFunctions) {
    bool ok = has(f.op);
    if (!ok) {
      why[std::string(f.key)] = "not supported by this edmplc";
    } else if (!f.manual.empty()) {
      const std::string flag(f.manual);
      ok = manual.is_object() && manual.contains(flag) && manual[flag].is_boolean() &&
           manual[flag].get<bool>();
      if (!ok) why[std::string(f.key)] = f.why;
    }
    caps[std::string(f.key)] = ok;
  }
  caps["work_coordinates"] = has("offset.get");
  caps["manual_status"] = has("manual.status");
  caps["why"] = std::move(why);
  return caps;
}

}  // namespace edm::hmi
