// Server reflection of driftlab-server, asked the way grpcurl and other generic clients ask:
// grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo with `list_services`. Debian ships
// the reflection server plugin but not its client stubs, so the request and the reply are
// encoded by hand from the wire format of reflection.proto (grpc/grpc, src/proto/grpc/reflection/
// v1alpha/reflection.proto): ServerReflectionRequest.list_services is field 7 (string);
// ServerReflectionResponse.list_services_response is field 6, a ListServiceResponse whose
// repeated field 1 holds ServiceResponse messages with the service name in field 1.
#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/io/zero_copy_stream_impl_lite.h>
#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "server_runner.h"

namespace driftlab::testing {
namespace {

using google::protobuf::io::CodedInputStream;

// Reads one length-delimited field's bytes; false at the end or on a malformed message.
bool NextField(CodedInputStream* in, uint32_t* field, std::string* bytes) {
  const uint32_t tag = in->ReadTag();
  if (tag == 0) return false;
  *field = tag >> 3;
  switch (tag & 7) {
    case 0: {  // varint
      uint64_t v;
      return in->ReadVarint64(&v) && (bytes->clear(), true);
    }
    case 2: {  // length-delimited
      uint32_t size;
      return in->ReadVarint32(&size) && in->ReadString(bytes, static_cast<int>(size));
    }
    default:
      return false;  // reflection replies use no other wire types
  }
}

// Waits for the completion-queue event `tag`; false on a failed operation or a timeout.
bool Await(grpc::CompletionQueue* cq, void* tag) {
  void* got = nullptr;
  bool ok = false;
  const auto deadline = std::chrono::system_clock::now() + std::chrono::seconds(10);
  if (cq->AsyncNext(&got, &ok, deadline) != grpc::CompletionQueue::GOT_EVENT) return false;
  return got == tag && ok;
}

// The four driftlab services must be listed (health is checked by jobs_service_test: the default
// health service has no descriptor in the generated pool, so reflection need not list it).
TEST(ServerReflection, ListServicesNamesEveryDriftlabService) {
  Scratch scratch;
  ServerProcess server(scratch.dir() / "data");
  ASSERT_TRUE(server.running()) << server.Log();
  auto channel = grpc::CreateChannel(server.address(), grpc::InsecureChannelCredentials());
  grpc::GenericStub stub(channel);
  grpc::ClientContext context;
  grpc::CompletionQueue cq;
  int tags[5];
  std::unique_ptr<grpc::GenericClientAsyncReaderWriter> call = stub.PrepareCall(
      &context, "/grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo", &cq);
  call->StartCall(&tags[0]);
  ASSERT_TRUE(Await(&cq, &tags[0]));

  // ServerReflectionRequest { list_services: "*" }: tag (7 << 3 | 2) = 0x3a, length 1, "*".
  const std::string request("\x3a\x01*", 3);
  grpc::Slice slice(request);
  grpc::ByteBuffer out(&slice, 1);
  call->Write(out, &tags[1]);
  ASSERT_TRUE(Await(&cq, &tags[1]));
  call->WritesDone(&tags[2]);
  ASSERT_TRUE(Await(&cq, &tags[2]));
  grpc::ByteBuffer in;
  call->Read(&in, &tags[3]);
  ASSERT_TRUE(Await(&cq, &tags[3]));
  grpc::Status status;
  call->Finish(&status, &tags[4]);
  ASSERT_TRUE(Await(&cq, &tags[4]));
  EXPECT_TRUE(status.ok()) << status.error_message();

  std::vector<grpc::Slice> slices;
  ASSERT_TRUE(in.Dump(&slices).ok());
  std::string reply;
  for (const grpc::Slice& s : slices)
    reply.append(reinterpret_cast<const char*>(s.begin()), s.size());

  std::set<std::string> services;
  google::protobuf::io::ArrayInputStream reply_stream(reply.data(), static_cast<int>(reply.size()));
  CodedInputStream response(&reply_stream);
  uint32_t field = 0;
  std::string bytes;
  while (NextField(&response, &field, &bytes)) {
    if (field != 6) continue;  // list_services_response
    CodedInputStream list(reinterpret_cast<const uint8_t*>(bytes.data()),
                          static_cast<int>(bytes.size()));
    std::string service;
    while (NextField(&list, &field, &service)) {
      if (field != 1) continue;  // ServiceResponse
      CodedInputStream entry(reinterpret_cast<const uint8_t*>(service.data()),
                             static_cast<int>(service.size()));
      std::string name;
      while (NextField(&entry, &field, &name)) {
        if (field == 1) services.insert(name);
      }
    }
  }
  for (const char* expected : {"driftlab.v1.Jobs", "driftlab.v1.Calibration", "driftlab.v1.Catalog",
                               "driftlab.v1.Datasets"}) {
    EXPECT_EQ(services.count(expected), 1u)
        << expected << " not listed; reply has " << services.size() << " services";
  }
  cq.Shutdown();
  void* tag;
  bool ok;
  while (cq.Next(&tag, &ok)) {
  }
}

}  // namespace
}  // namespace driftlab::testing
