// An ElasticOperator that forwards every call to a wrapped one: tests
// derive from it and override the one call they instrument (counting K
// builds, adding noise to the forces).
#pragma once

#include <memory>

#include "edgefem/core/elastic_operator.hpp"

namespace edgefem::test {

class ForwardingOperator : public ElasticOperator<double> {
public:
    explicit ForwardingOperator(std::unique_ptr<ElasticOperator<double>> op) : op_(std::move(op)) {}
    index_t num_vertices() const override { return op_->num_vertices(); }
    double forces(const double* u, double* f, bool energy) override { return op_->forces(u, f, energy); }
    double energy(const double* u) override { return op_->energy(u); }
    void build_stiffness(bool definite) override { op_->build_stiffness(definite); }
    void multiply(const double* x, double* y) const override { op_->multiply(x, y); }
    void diagonal_blocks(double* D) const override { op_->diagonal_blocks(D); }
    void for_each_block(void (*visit)(void*, index_t, index_t, const double*), void* ctx) const override {
        op_->for_each_block(visit, ctx);
    }
    index_t inverted_tets(const double* u) const override { return op_->inverted_tets(u); }

protected:
    std::unique_ptr<ElasticOperator<double>> op_;
};

}  // namespace edgefem::test
